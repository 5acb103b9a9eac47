//! Decomposition of every bone, findings (stretched, non-uniform, mirrored, degenerate), whole-clip analysis and
//! the reports built from them.

mod bind;
mod chunk;
mod clip_analysis;
mod compare;
mod findings;
pub mod report;
mod scan;
pub mod storage;
mod stretch;
mod subject;

pub use bind::{BindMismatch, BindTolerance, bind_mismatches};
pub use clip_analysis::{BoneSummary, ClipAnalysis, ClipScan, Components, Curves};
pub use compare::{BoneDifference, ClipComparison, compare};
pub use findings::{Assessment, Findings, Tolerances};
pub use scan::{analyze, scan};
pub use subject::{
    CurveRequest, GhostRequest, Judged, Layered, ScanOptions, Subject, layered_sample_times, sample_times,
};
