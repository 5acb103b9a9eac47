//! Decomposition of every bone, findings (stretched, non-uniform, mirrored, degenerate), whole-clip analysis and
//! the reports built from them.

mod bind;
mod chunk;
mod compare;
mod findings;
pub mod report;
mod scan;
pub mod storage;
mod stretch;

pub use bind::{BindMismatch, BindTolerance, bind_mismatches};
pub use compare::{BoneDifference, ClipComparison, compare};
pub use findings::{Assessment, Findings, Tolerances};
pub use scan::{
    BoneSummary, ClipAnalysis, ClipScan, Components, CurveRequest, Curves, GhostRequest, Judged, Layered, ScanOptions,
    Subject, analyze, layered_sample_times, sample_times, scan,
};
