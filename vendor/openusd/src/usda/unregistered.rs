//! bonescope: the attributes whose type this text reader does not know (`flaot[] weights = [1]`, a typo in one of
//! Pixar's own test files). Pixar's USD reads such a layer all the same: the attribute keeps its type name and its
//! value as the text written (`SdfUnregisteredValue`), and so does this reader ([`sdf::Value::UnregisteredValue`]).
//! Each is listed for the reading in progress, so that its caller can say what it could not read.

use std::cell::RefCell;

use crate::sdf;

/// An attribute of a type this reader does not know.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unregistered {
    pub attribute: sdf::Path,
    /// The type name as written (`flaot[]`).
    pub type_name: String,
}

thread_local! {
    /// The attributes found by the reading in progress on this thread, where one listens.
    static FOUND: RefCell<Option<Vec<Unregistered>>> = const { RefCell::new(None) };
}

/// Runs `read`; its result, and the attributes of unknown types the text layers it parsed hold.
pub fn within<R>(read: impl FnOnce() -> R) -> (R, Vec<Unregistered>) {
    let outer = FOUND.replace(Some(Vec::new()));
    let result = read();
    let found = FOUND.replace(outer).unwrap_or_default();
    (result, found)
}

/// Lists an attribute of unknown type, where a reading listens (once: its default and its time samples are two
/// declarations).
pub(crate) fn found(attribute: sdf::Path, type_name: String) {
    FOUND.with_borrow_mut(|found| {
        if let Some(found) = found.as_mut().filter(|found| found.iter().all(|u| u.attribute != attribute)) {
            found.push(Unregistered { attribute, type_name });
        }
    });
}
