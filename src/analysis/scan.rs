//! Whole-clip scans: every key time plus a fixed rate, every bone, in parallel, summarised per bone.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use super::{Assessment, Tolerances};
use crate::eval::{Hierarchy, Pose};
use crate::model::{Clip, Skeleton};

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

/// One bone over a whole clip. Times are in seconds.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BoneSummary {
    pub index: usize,
    pub worst_shear_deg: f64,
    /// When the worst shear happens (the first such time).
    pub worst_shear_time: f64,
    /// The largest angle of the stretch rotation among stretched samples (see [`Assessment::stretch_deg`]).
    pub worst_stretch_deg: f64,
    /// Samples where the bone is stretched.
    pub flagged_samples: usize,
    /// The first time it is stretched.
    pub first_flagged_time: Option<f64>,
    pub non_uniform_samples: usize,
    pub mirrored_samples: usize,
    pub degenerate_samples: usize,
}

impl BoneSummary {
    fn new(index: usize) -> Self {
        BoneSummary { index, ..BoneSummary::default() }
    }

    fn add(&mut self, time: f64, a: &Assessment) {
        if a.shear_deg > self.worst_shear_deg {
            self.worst_shear_deg = a.shear_deg;
            self.worst_shear_time = time;
        }
        let f = a.findings;
        if f.stretched {
            self.worst_stretch_deg = self.worst_stretch_deg.max(a.stretch_deg);
            self.flagged_samples += 1;
            self.first_flagged_time.get_or_insert(time);
        }
        self.non_uniform_samples += usize::from(f.non_uniform);
        self.mirrored_samples += usize::from(f.mirrored);
        self.degenerate_samples += usize::from(f.degenerate);
    }

    /// Combines the summary of an earlier stretch of time with that of a later one.
    fn merge(mut self, later: BoneSummary) -> BoneSummary {
        if later.worst_shear_deg > self.worst_shear_deg {
            self.worst_shear_deg = later.worst_shear_deg;
            self.worst_shear_time = later.worst_shear_time;
        }
        self.worst_stretch_deg = self.worst_stretch_deg.max(later.worst_stretch_deg);
        self.flagged_samples += later.flagged_samples;
        self.first_flagged_time = self.first_flagged_time.or(later.first_flagged_time);
        self.non_uniform_samples += later.non_uniform_samples;
        self.mirrored_samples += later.mirrored_samples;
        self.degenerate_samples += later.degenerate_samples;
        self
    }

    pub fn stretched(&self) -> bool {
        self.flagged_samples > 0
    }
}

/// The result of scanning one clip.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipScan {
    pub samples: usize,
    /// One per bone, in bone order.
    pub bones: Vec<BoneSummary>,
}

/// The times a scan visits: every key time, plus `0, 1/rate, 2/rate, …` up to the duration, plus the duration;
/// sorted, without duplicates. Just `[0]` without a clip.
pub fn sample_times(clip: Option<&Clip>, rate: f64) -> Vec<f64> {
    let Some(clip) = clip else { return vec![0.0] };
    let duration = clip.duration();
    let mut times = clip.key_times();
    if rate > 0.0 && rate.is_finite() {
        let steps = (duration * rate).floor() as usize;
        times.extend((0..=steps).map(|i| i as f64 / rate));
    }
    times.push(0.0);
    times.push(duration);
    times.sort_by(f64::total_cmp);
    times.dedup();
    times
}

/// Samples per parallel work item: big enough to amortise the buffers, small enough to balance two cores.
const CHUNK: usize = 64;

/// Scans `clip` (or the rest pose) under `hierarchy`'s modes. `progress(done, total)` is called from worker
/// threads as samples complete.
pub fn scan(
    skeleton: &Skeleton,
    clip: Option<&Clip>,
    hierarchy: &Hierarchy,
    options: &ScanOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> ClipScan {
    let times = sample_times(clip, options.rate);
    let done = AtomicUsize::new(0);
    let empty = || (0..skeleton.len()).map(BoneSummary::new).collect::<Vec<_>>();
    let bones = times
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut pose = Pose::default();
            let mut summaries = empty();
            for &time in chunk {
                pose.evaluate(skeleton, clip, hierarchy, time);
                for (summary, model) in summaries.iter_mut().zip(&pose.model.model) {
                    summary.add(time, &Assessment::of(model, &options.tolerances));
                }
            }
            progress(done.fetch_add(chunk.len(), Ordering::Relaxed) + chunk.len(), times.len());
            summaries
        })
        .reduce(empty, |earlier, later| earlier.into_iter().zip(later).map(|(a, b)| a.merge(b)).collect());
    ClipScan { samples: times.len(), bones }
}
