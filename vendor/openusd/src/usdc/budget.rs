//! bonescope: a memory budget for what a crate file's counts make the reader allocate. Each array is charged before
//! it is read, from the count its header gives: a file whose arrays would take more than the budget is refused
//! before they are allocated, however far its bytes bear the counts out. An array dropped once it has been handed on
//! (a streamed time sample's) is released, so the budget bounds what is held at once.

use std::cell::Cell;

use anyhow::{bail, Result};

/// A reading's budget: its limit, what its arrays hold now, and the most they held at once.
#[derive(Clone, Copy)]
struct Budget {
    limit: u64,
    held: u64,
    peak: u64,
}

thread_local! {
    /// The budget of the reading in progress on this thread.
    static BUDGET: Cell<Option<Budget>> = const { Cell::new(None) };
}

/// Runs `read` with `limit` bytes for the arrays it decodes; its result, and the most bytes its arrays held at once
/// (up to the first that did not fit).
pub fn within<R>(limit: u64, read: impl FnOnce() -> R) -> (R, u64) {
    let outer = BUDGET.replace(Some(Budget { limit, held: 0, peak: 0 }));
    let result = read();
    let peak = BUDGET.replace(outer).map_or(0, |budget| budget.peak);
    (result, peak)
}

/// Charges `count` elements of `size` bytes to the budget, where one is set (public: a reader that builds arrays of
/// its own from what a visit hands it charges them too).
pub fn charge(count: usize, size: usize) -> Result<()> {
    charge_bytes((count as u64).saturating_mul(size as u64))
}

/// Charges `bytes` to the budget, where one is set.
pub(crate) fn charge_bytes(bytes: u64) -> Result<()> {
    let Some(mut budget) = BUDGET.get() else { return Ok(()) };
    budget.held = budget.held.saturating_add(bytes);
    budget.peak = budget.peak.max(budget.held);
    BUDGET.set(Some(budget));
    if budget.held > budget.limit {
        bail!("its arrays need {} bytes, over the reader's budget of {}", budget.held, budget.limit);
    }
    Ok(())
}

/// Gives back `bytes` charged for arrays that are dropped.
pub(crate) fn release(bytes: u64) {
    if let Some(mut budget) = BUDGET.get() {
        budget.held = budget.held.saturating_sub(bytes);
        BUDGET.set(Some(budget));
    }
}

/// What the arrays charged hold now (0 without a budget).
pub(crate) fn held() -> u64 {
    BUDGET.get().map_or(0, |budget| budget.held)
}
