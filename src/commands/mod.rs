//! One module per subcommand; `run` dispatches.

use std::process::ExitCode;

use crate::cli::{Cli, Command};

pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        None => anyhow::bail!("the sandbox window is not built yet; try `octovox info FILE`"),
        Some(Command::Info { .. }) | Some(Command::Convert { .. }) => {
            anyhow::bail!("not implemented yet")
        }
    }
}
