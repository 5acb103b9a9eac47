//! Decomposition of every bone, findings (stretched, non-uniform, mirrored, degenerate), whole-clip analysis and
//! the reports built from them.

mod bind;
mod chunk;
mod clip_analysis;
mod findings;
mod peak;
pub mod report;
mod request;
mod sampled;
mod scan;
pub mod sketch;
pub mod storage;
mod stretch;
mod variants;

pub use bind::{BindCheck, BindGap, BindMismatch, BindTolerance, ClipFrame, check_bind};
pub use clip_analysis::{BoneSummary, ClipAnalysis, ClipScan, Components, Curves, SAME_SHEAR_DEG};
pub use findings::{Assessment, Findings, STRETCHED_RGB, Tolerances, shear_rgb};
pub(crate) use peak::{around, gains};
pub use request::{CurveRequest, Judged, ScanOptions};
pub use sampled::{Sampled, sample};
pub use scan::{analyze, clearly_flagged_at, flagged_in_run, scan, scan_analysis};
pub use variants::{JudgedRun, VariantJudges, scan_variants};
