//! One module per subcommand; `run` dispatches.

mod convert;
mod info;
pub mod render;

use std::process::ExitCode;

use crate::cli::{Cli, Command};

pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        None => crate::app::run(cli.window),
        Some(Command::Info { file, json, frame }) => info::run(&file, json, frame),
        Some(Command::Convert {
            input,
            output,
            frame,
        }) => convert::run(&input, &output, frame),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Bench(_)) => anyhow::bail!("bench is not built yet"),
    }
}
