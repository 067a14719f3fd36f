//! One module per subcommand; `run` dispatches.

/// `println!` that returns a write error (such as a closed pipe, which
/// `main` treats as a normal end) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}

mod bench;
mod bench_anim;
mod bench_effects;
mod bench_quality;
mod bench_scale;
mod bench_scene;
mod bench_turns;
mod benches;
mod convert;
mod export;
mod import;
mod info;
mod progress_bar;
mod quality_plot;
mod recover;
pub mod render;
mod render_frames;
mod replay;

use std::process::ExitCode;

use crate::cli::{Cli, CliCommand};

/// `OCTOVOX_UPDATE_IMAGES=1` makes `expect image` write its reference.
fn update_images() -> bool {
    std::env::var_os("OCTOVOX_UPDATE_IMAGES").is_some_and(|v| v == "1")
}

pub fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    octovox::budget::set_budget_bytes(cli.memory_budget);
    match cli.command {
        None => crate::app::run(cli.window),
        Some(CliCommand::Info { file, json, objects, frame }) => info::run(&file, json, objects, frame),
        Some(CliCommand::Convert { input, output, frame, force }) => convert::run(&input, &output, frame, force),
        Some(CliCommand::Import(args)) => import::run(&args),
        Some(CliCommand::Recover { file, output, force }) => recover::run(&file, &output, force),
        Some(CliCommand::Export { file, output, scale, frame, force }) => {
            export::run(&file, &output, scale, frame, force)
        }
        Some(CliCommand::Render(args)) => render::run(&args),
        Some(CliCommand::Bench(args)) => benches::run(&args),
        Some(CliCommand::Replay { scripts, cpu, force }) => replay::run(&scripts, cpu, force, update_images()),
    }
}
