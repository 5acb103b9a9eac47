//! Panics caught at the USD importer's edge: the `openusd` crate may panic on a file it does not expect (a bug
//! there), and one file must not end a library scan or the app. While a guarded call runs, a panic on its thread is
//! not printed (its message becomes the file's error, one line); every other panic is printed as before.

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;

thread_local! {
    /// Whether this thread is in a guarded call.
    static GUARDED: Cell<bool> = const { Cell::new(false) };
}

/// `f()`, or the message of the panic it raised.
pub fn caught<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    quiet_while_guarded();
    let was = GUARDED.replace(true);
    let result = catch_unwind(AssertUnwindSafe(f));
    GUARDED.set(was);
    result.map_err(|payload| {
        let text = payload.downcast_ref::<&str>().map(|s| s.to_string());
        text.or_else(|| payload.downcast_ref::<String>().cloned()).unwrap_or_else(|| "a panic".to_owned())
    })
}

/// Wraps the process's panic hook, once, so that it says nothing for a guarded thread.
fn quiet_while_guarded() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !GUARDED.get() {
                previous(info);
            }
        }));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_is_a_message_and_the_guard_is_lifted_after() {
        assert_eq!(caught(|| 7), Ok(7));
        assert_eq!(caught(|| -> u8 { panic!("index out of bounds") }), Err("index out of bounds".to_owned()));
        let formatted = caught(|| -> u8 { panic!("{} of {}", 3, 2) });
        assert_eq!(formatted, Err("3 of 2".to_owned()));
        assert!(!GUARDED.get());
    }
}
