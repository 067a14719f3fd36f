use std::process::ExitCode;

use clap::Parser;

mod app;
mod cli;
mod commands;

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = cli::Cli::parse();
    match commands::run(cli) {
        Ok(code) => code,
        Err(err) => {
            eprintln!("octovox: error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
