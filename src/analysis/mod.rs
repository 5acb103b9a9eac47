//! Decomposition of every bone, findings (stretched, non-uniform, mirrored, degenerate), whole-clip scans and the
//! reports built from them.

mod compare;
mod findings;
pub mod report;
mod scan;

pub use compare::{BoneDifference, ClipComparison, compare};
pub use findings::{Assessment, Findings, Tolerances};
pub use scan::{BoneSummary, ClipScan, ScanOptions, sample_times, scan};
