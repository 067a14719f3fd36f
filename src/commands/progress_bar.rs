//! A terminal progress bar (indicatif) over a long step: the step runs on
//! a scoped thread and reports to an `octovox::io::progress::Progress`; this
//! thread draws it. Nothing is drawn when stderr is not a terminal.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use octovox::io::progress::Progress;

/// A bar named `what` over `total` steps, on stderr (indicatif draws
/// nothing where stderr is not a terminal).
pub fn bar(what: &str, total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total).with_message(what.to_string());
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {percent}% {elapsed}").unwrap_or(ProgressStyle::default_bar()),
    );
    bar
}

/// A bar over the `total` frames of a render, with the time left.
pub fn frames_bar(total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("rendering [{bar:30}] {pos}/{len} frames, {eta} left")
            .unwrap_or(ProgressStyle::default_bar()),
    );
    bar
}

/// Runs `work` with a progress it reports to, showing a bar named `what`.
pub fn with_bar<T: Send>(what: &str, work: impl FnOnce(&Progress) -> T + Send) -> T {
    let progress = Progress::default();
    let bar = bar(what, 0);
    let result = std::thread::scope(|scope| {
        let worker = scope.spawn(|| work(&progress));
        while !worker.is_finished() {
            let (done, total) = progress.get();
            bar.set_length(total.max(1));
            bar.set_position(done);
            std::thread::sleep(Duration::from_millis(100));
        }
        worker.join()
    });
    bar.finish_and_clear();
    // A panic in the worker is the worker's: pass it on as it was.
    result.unwrap_or_else(|panic| std::panic::resume_unwind(panic))
}
