//! File formats: MagicaVoxel .vox in and out.

pub mod vox;
