//! MagicaVoxel .vox loading and saving (to be written).
