//! Which load of a rig a result was computed from.

use std::sync::atomic::{AtomicU64, Ordering};

/// One load of a rig: what every result computed from it is keyed by, so that another file, or the same file read
/// again, is measured anew even where its bones are the same.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RigId(u64);

impl RigId {
    /// An identity no rig had before.
    pub fn fresh() -> RigId {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        RigId(NEXT.fetch_add(1, Ordering::Relaxed))
    }
}
