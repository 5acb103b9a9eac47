//! Decomposition of every bone, findings (stretched, non-uniform, mirrored, degenerate), whole-clip analysis and
//! the reports built from them.

mod compare;
mod findings;
pub mod report;
mod scan;

pub use compare::{BoneDifference, ClipComparison, compare};
pub use findings::{Assessment, Findings, Tolerances};
pub use scan::{
    BoneSummary, ClipAnalysis, ClipScan, Components, CurveRequest, Curves, ScanOptions, analyze, sample_times, scan,
};
