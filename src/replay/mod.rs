//! Running scripts: the interpreter that carries out every line for a
//! host (`octovox replay` headless, or the window), and the recorder that
//! writes a window session (or the crash journal) as a script.

mod record;
mod run;
mod step;

pub use record::Recorder;
pub use run::{Failure, Runner, RunnerMode, ScriptReport};
pub use step::{DEFAULT_VIEWPORT, Host, HostError, Ran, StepError, StepResult, step};
