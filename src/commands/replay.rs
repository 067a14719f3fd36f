//! `octovox replay SCRIPT...`: runs scripts headless and reports.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;

use octovox::gpu::Renderer;
use octovox::replay::{Runner, RunnerMode};
use octovox::script::load_script;

pub fn run(scripts: &[PathBuf], cpu: bool, force: bool, update_images: bool) -> anyhow::Result<ExitCode> {
    let mut mode = if cpu {
        RunnerMode::Cpu
    } else {
        RunnerMode::Gpu(Box::new(Renderer::headless().context("no GPU for replay (try --cpu)")?))
    };
    let (mut passed, mut failed) = (0, 0);
    for path in scripts {
        let script = match load_script(path) {
            Ok(script) => script,
            Err(errors) => {
                for error in &errors {
                    say!("{error}")?;
                }
                failed += errors.len();
                continue;
            }
        };
        let mut runner = Runner::new(mode);
        runner.update_images = update_images;
        runner.force = force;
        let report = runner.run(&script);
        for failure in &report.failures {
            say!("{failure}")?;
        }
        passed += report.passed;
        failed += report.failures.len();
        mode = runner.into_mode();
    }
    say!("replay: {passed} passed, {failed} failed")?;
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
