//! How far a long load or import has got: a pair of counters the worker
//! advances and a window or terminal reads from another thread.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// Done and total units of work (tiles of columns, bytes); cheap to clone,
/// every clone the same counters. A `Progress::default()` nobody reads costs
/// two relaxed atomic writes per step.
#[derive(Clone, Debug, Default)]
pub struct Progress(Arc<[AtomicU64; 2]>);

impl Progress {
    /// Starts over with `total` units to do.
    pub fn start(&self, total: u64) {
        self.0[0].store(0, Ordering::Relaxed);
        self.0[1].store(total, Ordering::Relaxed);
    }

    pub fn advance(&self, units: u64) {
        self.0[0].fetch_add(units, Ordering::Relaxed);
    }

    /// Units done and the total; the total is 0 before anyone started.
    pub fn get(&self) -> (u64, u64) {
        (self.0[0].load(Ordering::Relaxed), self.0[1].load(Ordering::Relaxed))
    }

    /// The fraction done, once a total is known.
    pub fn fraction(&self) -> Option<f32> {
        let (done, total) = self.get();
        (total > 0).then(|| (done as f64 / total as f64).min(1.0) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_their_counters() {
        let progress = Progress::default();
        assert_eq!(progress.fraction(), None);
        let worker = progress.clone();
        worker.start(4);
        worker.advance(1);
        assert_eq!(progress.fraction(), Some(0.25));
        worker.advance(9);
        assert_eq!(progress.fraction(), Some(1.0));
    }
}
