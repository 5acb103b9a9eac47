//! bonescope: a memory budget for what a crate file's counts make the reader allocate. Each array is charged before
//! it is read, from the count its header gives: a file whose arrays would take more than the budget is refused
//! before they are allocated, however far its bytes bear the counts out.

use std::cell::Cell;

use anyhow::{bail, Result};

thread_local! {
    /// The budget of the reading in progress on this thread, and what has been charged to it.
    static BUDGET: Cell<Option<(u64, u64)>> = const { Cell::new(None) };
}

/// Runs `read` with `limit` bytes for the arrays it decodes; its result, and the bytes charged (what the arrays
/// needed, up to the first that did not fit).
pub fn within<R>(limit: u64, read: impl FnOnce() -> R) -> (R, u64) {
    let outer = BUDGET.replace(Some((limit, 0)));
    let result = read();
    let charged = BUDGET.replace(outer).map_or(0, |(_, charged)| charged);
    (result, charged)
}

/// Charges `count` elements of `size` bytes to the budget, where one is set (public: a reader that builds arrays of
/// its own from what a visit hands it charges them too).
pub fn charge(count: usize, size: usize) -> Result<()> {
    let Some((limit, charged)) = BUDGET.get() else { return Ok(()) };
    let charged = charged.saturating_add((count as u64).saturating_mul(size as u64));
    BUDGET.set(Some((limit, charged)));
    if charged > limit {
        bail!("its arrays need {charged} bytes, over the reader's budget of {limit}");
    }
    Ok(())
}
