//! What a whole-clip analysis is asked besides its [`Evaluation`]: the options, and which bones' curves it keeps.

use super::Tolerances;
use crate::eval::Evaluation;

/// How a clip is scanned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanOptions {
    /// Samples per second on top of the key times (default 60).
    pub rate: f64,
    pub tolerances: Tolerances,
}

impl Default for ScanOptions {
    fn default() -> Self {
        ScanOptions { rate: 60.0, tolerances: Tolerances::default() }
    }
}

/// What a whole-clip analysis computes besides the per-bone summaries.
#[derive(Clone, Copy, Debug, Default)]
pub struct CurveRequest<'a> {
    /// Bones whose full curves are kept (indices past the skeleton's end are left out).
    pub bones: &'a [usize],
    /// A second evaluation of the same rig and clip (other modes, or without the layers): those bones' ghost
    /// curves.
    pub ghost: Option<&'a Evaluation<'a>>,
    /// Which bones are judged.
    pub judged: Judged,
}

/// Which bones an analysis judges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Judged {
    /// Every bone: the whole-clip summary of the rig.
    #[default]
    Every,
    /// Only the bones whose curves are asked for and their ancestors: the curves of a newly selected bone, without
    /// waiting for the rest of the rig (the other bones' summaries stay empty).
    CurveChains,
    /// Only this bone, the bones below it and its ancestors: what a change to that bone alone can change (the
    /// other bones' summaries stay empty).
    Subtree(usize),
    /// Only this bone and its ancestors: what its own verdicts need.
    Chain(usize),
}
