//! Third-party parsers (dot_vox, tobj) run under a guard: a panic inside
//! them becomes an error message, so bad input never takes the program down.

use std::cell::Cell;
use std::panic::{self, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// Set while this thread is inside [`catch_quietly`], so the panic hook
    /// stays quiet.
    static QUIET_PANICS: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`, returning a panic's message as `Err` instead of unwinding.
///
/// A panic hook, installed once, skips panics raised on a thread while it is
/// inside this function and passes every other panic to the hook it
/// replaced, so the caught panic does not print while other threads' panics
/// still do.
pub(crate) fn catch_quietly<T>(f: impl FnOnce() -> T) -> Result<T, Panicked> {
    static INSTALL_HOOK: Once = Once::new();
    INSTALL_HOOK.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if !QUIET_PANICS.try_with(Cell::get).unwrap_or(false) {
                previous(info);
            }
        }));
    });
    let was_quiet = QUIET_PANICS.replace(true);
    // Callers only read shared data, so no broken invariant leaks out of a panic.
    let result = panic::catch_unwind(AssertUnwindSafe(f));
    QUIET_PANICS.set(was_quiet);
    result.map_err(|payload| {
        Panicked(
            payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_owned()),
        )
    })
}

/// A parser's panic, caught: its message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Panicked(pub String);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panics_become_errors() {
        assert_eq!(catch_quietly(|| 7), Ok(7));
        let boom: Result<(), Panicked> = catch_quietly(|| panic!("boom {}", 1));
        assert_eq!(boom, Err(Panicked("boom 1".to_owned())));
        // The thread is loud again afterwards.
        assert!(!QUIET_PANICS.get());
    }
}
