//! What a whole-clip analysis is asked: the subject (a skeleton's clip, directly or through layers), the times it
//! visits, the options, and which bones' curves it keeps.

use super::Tolerances;
use crate::eval::{Hierarchy, LayerStack, Pose};
use crate::model::{Clip, Rig, Skeleton};

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
    /// A second evaluation of those bones, kept as their ghost curves.
    pub ghost: Option<GhostRequest<'a>>,
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
}

/// How the ghost curves are evaluated: under other modes, and with or without the analysis's layers.
#[derive(Clone, Copy, Debug)]
pub struct GhostRequest<'a> {
    pub hierarchy: &'a Hierarchy,
    /// The clip as authored, without the layers (for comparing a layer's result with its input).
    pub unlayered: bool,
}

/// The most frames of the scan rate a clip is visited at every one of; a longer clip is visited at its key times and
/// a bounded number of times between sparse keys ([`crate::model::sample_times`]).
const MAX_FRAMES: usize = 1 << 20;

/// The times a scan visits: every key time, plus `0, 1/rate, 2/rate, …` up to the duration, plus the duration;
/// sorted, without duplicates (thinned between sparse keys for a clip of more than `MAX_FRAMES` (2²⁰) frames). Just
/// `[0]` without a clip.
pub fn sample_times(clip: Option<&Clip>, rate: f64) -> Vec<f64> {
    let Some(clip) = clip else { return vec![0.0] };
    crate::model::sample_times(clip.key_times(), 0.0, clip.duration(), rate, MAX_FRAMES).times
}

/// The times a layered scan visits: [`sample_times`] of the main clip, unless the layers change the timeline (a
/// synced blend plays a cycle of another length, a crossfade runs on into the incoming clip): then the grid
/// `0, 1/rate, …` over the layered duration, plus its end.
pub fn layered_sample_times(rig: &Rig, clip: Option<&Clip>, layers: &LayerStack, rate: f64) -> Vec<f64> {
    let duration = layers.duration(rig, clip);
    if layers.synced_cycle(rig, clip).is_none() && duration == clip.map_or(0.0, Clip::duration) {
        return sample_times(clip, rate);
    }
    crate::model::sample_times([], 0.0, duration, rate, MAX_FRAMES).times
}

/// A rig evaluated through layers.
#[derive(Clone, Copy, Debug)]
pub struct Layered<'a> {
    pub rig: &'a Rig,
    /// Built for `rig`; each worker thread evaluates its own copy.
    pub layers: &'a LayerStack,
}

/// What an analysis evaluates at each sample time: a skeleton's clip (the rest pose for `None`), directly or through
/// layers.
#[derive(Clone, Copy, Debug)]
pub struct Subject<'a> {
    pub skeleton: &'a Skeleton,
    pub clip: Option<&'a Clip>,
    pub layered: Option<Layered<'a>>,
}

impl<'a> Subject<'a> {
    /// The clip as sampled.
    pub fn clip(skeleton: &'a Skeleton, clip: Option<&'a Clip>) -> Self {
        Subject { skeleton, clip, layered: None }
    }

    /// The clip through layers (`clip` is their main clip). Layers that leave the clip as it is are no layers: the
    /// clip is then sampled directly, which lets a fully inheriting rig be judged bone by bone (`chunk.rs`).
    pub fn layered(layered: Layered<'a>, clip: Option<&'a Clip>) -> Self {
        let layers = Some(layered).filter(|l| !l.layers.is_empty());
        Subject { skeleton: &layered.rig.skeleton, clip, layered: layers }
    }
}

impl Subject<'_> {
    /// A worker's own copy of the layers (`None` without layers).
    pub(super) fn worker_layers(&self) -> Option<LayerStack> {
        self.layered.map(|l| l.layers.clone())
    }

    pub(super) fn evaluate(&self, pose: &mut Pose, hierarchy: &Hierarchy, layers: &mut Option<LayerStack>, time: f64) {
        match (self.layered, layers) {
            (Some(layered), Some(stack)) => pose.evaluate_layered(layered.rig, self.clip, hierarchy, stack, time),
            _ => pose.evaluate(self.skeleton, self.clip, hierarchy, time),
        }
    }

    pub(super) fn times(&self, rate: f64) -> Vec<f64> {
        match self.layered {
            Some(l) => layered_sample_times(l.rig, self.clip, l.layers, rate),
            None => sample_times(self.clip, rate),
        }
    }
}
