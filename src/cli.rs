//! Command-line interface: one enum variant per subcommand.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(name = "octovox", version, about = "Voxel sandbox with a GPU sparse-voxel-octree ray tracer")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Print what a .vox file holds: models, voxels, extent, palette and materials used.
    Info {
        file: PathBuf,
        /// Machine-readable output.
        #[arg(long)]
        json: bool,
        /// Animation frame to read (files with several models and no scene graph).
        #[arg(long, default_value_t = 0)]
        frame: usize,
    },
    /// Load a .vox and save it again through octovox's scene model.
    Convert {
        input: PathBuf,
        output: PathBuf,
        #[arg(long, default_value_t = 0)]
        frame: usize,
    },
}
