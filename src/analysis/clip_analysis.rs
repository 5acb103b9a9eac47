//! What a whole-clip analysis gives: per-bone summaries, per-sample stretched flags, and the decomposed components
//! of the bones asked for.

use glam::{DMat4, DQuat, DVec3, Quat, Vec3};
use rayon::prelude::*;

use super::findings::{Tolerances, Verdict, shear_cosine};
use super::peak::{self, Peaks};
use crate::math::{AffineParts, angle_of_half_cosine, decompose_near, shear_deg_of_cosine};

/// One bone over a whole clip. Times are in seconds.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BoneSummary {
    pub index: usize,
    pub worst_shear_deg: f64,
    /// When the worst shear happens (the first such time).
    pub worst_shear_time: f64,
    /// The largest angle of the stretch rotation among stretched samples (see [`super::Assessment::stretch_deg`]).
    pub worst_stretch_deg: f64,
    /// Samples where the bone is stretched.
    pub flagged_samples: usize,
    /// The first time it is stretched.
    pub first_flagged_time: Option<f64>,
    pub non_uniform_samples: usize,
    pub mirrored_samples: usize,
    pub degenerate_samples: usize,
    /// The worst shear and stretch as the cosines of [`Verdict`], turned into angles once at the end.
    #[serde(skip)]
    pub(super) worst_shear_cosine_squared: f64,
    #[serde(skip)]
    worst_stretch_half_cosine: f64,
    /// The highest peaks of the sampled shear, where [`BoneSummary::refine_shear`] searches between samples.
    #[serde(skip)]
    shear_peaks: Peaks,
}

impl BoneSummary {
    pub(super) fn new(index: usize) -> Self {
        BoneSummary {
            index,
            worst_shear_deg: 0.0,
            worst_shear_time: 0.0,
            worst_stretch_deg: 0.0,
            flagged_samples: 0,
            first_flagged_time: None,
            non_uniform_samples: 0,
            mirrored_samples: 0,
            degenerate_samples: 0,
            worst_shear_cosine_squared: 0.0,
            worst_stretch_half_cosine: 1.0,
            shear_peaks: Peaks::default(),
        }
    }

    /// Adds one sample. The worst angles are kept as cosines until [`BoneSummary::finish`].
    pub(super) fn add(&mut self, time: f64, verdict: &Verdict) {
        self.shear_peaks.add(time, verdict.shear_cosine_squared);
        if verdict.shear_cosine_squared > self.worst_shear_cosine_squared {
            self.worst_shear_cosine_squared = verdict.shear_cosine_squared;
            self.worst_shear_time = time;
        }
        let f = verdict.findings;
        if f.stretched {
            self.worst_stretch_half_cosine = self.worst_stretch_half_cosine.min(verdict.stretch_half_cosine);
            self.flagged_samples += 1;
            self.first_flagged_time.get_or_insert(time);
        }
        self.non_uniform_samples += usize::from(f.non_uniform);
        self.mirrored_samples += usize::from(f.mirrored);
        self.degenerate_samples += usize::from(f.degenerate);
    }

    /// Combines the summary of an earlier run of samples with that of a later one.
    pub(super) fn merge(&mut self, later: &BoneSummary) {
        self.shear_peaks.merge(&later.shear_peaks);
        if later.worst_shear_cosine_squared > self.worst_shear_cosine_squared {
            self.worst_shear_cosine_squared = later.worst_shear_cosine_squared;
            self.worst_shear_time = later.worst_shear_time;
        }
        self.worst_stretch_half_cosine = self.worst_stretch_half_cosine.min(later.worst_stretch_half_cosine);
        self.flagged_samples += later.flagged_samples;
        self.first_flagged_time = self.first_flagged_time.or(later.first_flagged_time);
        self.non_uniform_samples += later.non_uniform_samples;
        self.mirrored_samples += later.mirrored_samples;
        self.degenerate_samples += later.degenerate_samples;
    }

    /// Adds `count` more samples with the same verdict as the last one added (at later times).
    pub(super) fn repeat(&mut self, count: usize, verdict: &Verdict) {
        let f = verdict.findings;
        self.flagged_samples += count * usize::from(f.stretched);
        self.non_uniform_samples += count * usize::from(f.non_uniform);
        self.mirrored_samples += count * usize::from(f.mirrored);
        self.degenerate_samples += count * usize::from(f.degenerate);
    }

    /// Refines the worst shear between the samples at `times` (those this summary was made of): `shear_at(time)` is
    /// the bone's shear there as its cosine squared.
    pub(super) fn refine_shear(&mut self, times: &[f64], shear_at: impl FnMut(f64) -> f64) {
        let sampled = (self.worst_shear_time, self.worst_shear_cosine_squared);
        (self.worst_shear_time, self.worst_shear_cosine_squared) =
            peak::refine(&self.shear_peaks, times, sampled, shear_at);
        self.finish();
    }

    /// Turns the worst cosines into angles.
    pub(super) fn finish(&mut self) {
        self.worst_shear_deg = shear_deg_of_cosine(self.worst_shear_cosine_squared.sqrt());
        self.worst_stretch_deg = angle_of_half_cosine(self.worst_stretch_half_cosine);
    }

    pub fn stretched(&self) -> bool {
        self.flagged_samples > 0
    }
}

/// Shears within this many degrees of each other are the same shear, apart by rounding alone (two bones whose
/// matrices differ by a translation; one bone's shear evaluated along another path): orders of bones and fixes by
/// shear treat them as equal, so that a last bit does not decide.
pub const SAME_SHEAR_DEG: f64 = 1e-9;

/// The result of scanning one clip.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipScan {
    pub samples: usize,
    /// One per bone, in bone order.
    pub bones: Vec<BoneSummary>,
}

impl ClipScan {
    /// The bones stretched somewhere in the clip, the worst shear first (to [`SAME_SHEAR_DEG`]; ties in bone order).
    pub fn stretched_worst_first(&self) -> Vec<&BoneSummary> {
        let mut bones: Vec<&BoneSummary> = self.bones.iter().filter(|b| b.stretched()).collect();
        let shear = |b: &BoneSummary| (b.worst_shear_deg / SAME_SHEAR_DEG).round();
        bones.sort_by(|a, b| shear(b).total_cmp(&shear(a)));
        bones
    }
}

/// The decomposed parts of one matrix at one sample, in single precision (plots need no more, and long clips
/// stay small).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Components {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
    pub stretch: Quat,
    pub sign: f32,
    pub shear_deg: f32,
}

impl Components {
    /// A placeholder for a sample not computed yet.
    const UNSET: Components = Components {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        scale: Vec3::ZERO,
        stretch: Quat::IDENTITY,
        sign: 1.0,
        shear_deg: 0.0,
    };

    /// The components of `m`, its decomposition searching from `start` (see [`decompose_near`]; the previous
    /// sample's stretch makes a curve faster).
    pub fn of_matrix(m: &DMat4, start: DQuat) -> Self {
        Components::of_parts(&decompose_near(m, start), m)
    }

    /// The components of `m` decomposed into `parts`; the stretch frame is the one the findings judge (factors
    /// within the default anisotropy tolerance count as equal: [`AffineParts::stretch_within`]), so a plotted
    /// stretch angle is the scan's and the Inspector's.
    pub(super) fn of_parts(parts: &AffineParts, m: &DMat4) -> Self {
        let shear_deg = shear_deg_of_cosine(shear_cosine(parts, m));
        Components {
            translation: parts.translation.as_vec3(),
            rotation: parts.rotation.as_quat(),
            scale: parts.scale.as_vec3(),
            stretch: parts.stretch_within(Tolerances::default().min_anisotropy).as_quat(),
            sign: parts.sign as f32,
            shear_deg: shear_deg as f32,
        }
    }

    /// The translation in double precision, for callers that compare positions.
    pub fn position(&self) -> DVec3 {
        self.translation.as_dvec3()
    }
}

/// One bone's components at every sample time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curves {
    pub local: Vec<Components>,
    pub model: Vec<Components>,
    /// The model-space components under the ghost modes, when asked for.
    pub ghost_model: Vec<Components>,
}

impl Curves {
    /// Curves of `samples` samples (and ghost curves, or none), to be overwritten: the chunks of an analysis write
    /// their parts in place. Filled in parallel, so that long clips' hundreds of megabytes are not first touched
    /// on one thread.
    pub(super) fn for_samples(samples: usize, ghost: bool) -> Self {
        let unset = || {
            let mut curve = Vec::new();
            rayon::iter::repeat_n(Components::UNSET, samples).collect_into_vec(&mut curve);
            curve
        };
        Curves { local: unset(), model: unset(), ghost_model: if ghost { unset() } else { Vec::new() } }
    }
}

/// A whole clip analysed: per-bone summaries, per-bone per-sample stretched flags, and curves of chosen bones.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipAnalysis {
    pub times: Vec<f64>,
    pub scan: ClipScan,
    /// Bit `s` of bone `b`'s row: stretched at sample `s`. Rows of `words_per_bone` words.
    pub(super) stretched_bits: Vec<u64>,
    pub(super) words_per_bone: usize,
    /// Bit `s`: some bone of the figure is stretched at sample `s` (a camera under a squashed parent is no
    /// character's problem: [`crate::model::Skeleton::figure`]).
    pub(super) any_stretched_bits: Vec<u64>,
    /// `(bone, curves)` for the requested bones, in request order.
    pub curves: Vec<(usize, Curves)>,
}

impl ClipAnalysis {
    /// Whether `bone` is stretched at sample `sample`.
    pub fn stretched_at(&self, bone: usize, sample: usize) -> bool {
        let word = self.stretched_bits.get(bone * self.words_per_bone + sample / 64).copied().unwrap_or(0);
        word >> (sample % 64) & 1 == 1
    }

    /// Whether any bone of the figure is stretched at sample `sample`.
    pub fn any_stretched_at(&self, sample: usize) -> bool {
        self.any_stretched_bits.get(sample / 64).is_some_and(|word| word >> (sample % 64) & 1 == 1)
    }

    /// The time spans in which `bone` (or, for `None`, any bone of the figure) is stretched: from the first flagged sample to
    /// the first sample after it that is not (or the last sample).
    pub fn stretched_spans(&self, bone: Option<usize>) -> Vec<(f64, f64)> {
        let flagged = |s: usize| bone.map_or_else(|| self.any_stretched_at(s), |b| self.stretched_at(b, s));
        let mut spans = Vec::new();
        let mut start = None;
        for (sample, &time) in self.times.iter().enumerate() {
            match (start, flagged(sample)) {
                (None, true) => start = Some(time),
                (Some(from), false) => {
                    spans.push((from, time));
                    start = None;
                }
                _ => {}
            }
        }
        if let (Some(from), Some(&last)) = (start, self.times.last()) {
            spans.push((from, last));
        }
        spans
    }

    pub fn curves_of(&self, bone: usize) -> Option<&Curves> {
        self.curves.iter().find(|(b, _)| *b == bone).map(|(_, c)| c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bones_whose_worst_shears_differ_by_rounding_alone_stay_in_bone_order() {
        // Maya's mixed-inheritance test file: a bone and its tip shear the same 20.556°, one ulp apart.
        let shear: f64 = 20.556044824203433;
        let bone = |index: usize, worst_shear_deg: f64| BoneSummary {
            worst_shear_deg,
            flagged_samples: 1,
            ..BoneSummary::new(index)
        };
        let scan =
            ClipScan { samples: 1, bones: vec![bone(0, 3.0), bone(1, shear), bone(2, shear.next_up()), bone(3, 30.0)] };
        let order: Vec<usize> = scan.stretched_worst_first().iter().map(|b| b.index).collect();
        assert_eq!(order, [3, 1, 2, 0]);
    }
}
