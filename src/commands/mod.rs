//! One module per subcommand; `run` dispatches.

mod bench;
mod convert;
mod import;
mod info;
pub mod render;
mod replay;

use std::process::ExitCode;

use crate::cli::{Cli, Command};

/// `OCTOVOX_UPDATE_IMAGES=1` makes `expect image` write its reference.
fn update_images() -> bool {
    std::env::var_os("OCTOVOX_UPDATE_IMAGES").is_some_and(|v| v == "1")
}

pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        None => crate::app::run(cli.window),
        Some(Command::Info { file, json, frame }) => info::run(&file, json, frame),
        Some(Command::Convert { input, output, frame }) => convert::run(&input, &output, frame),
        Some(Command::Import(args)) => import::run(&args),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Replay { scripts, cpu }) => replay::run(&scripts, cpu, update_images()),
    }
}
