//! The times a clip is baked at first: every frame of the clip's rate, every key time, a moment before every
//! stepped key (its lead: the value just before the jump), and the quarter points between the keys of cubic-spline
//! tracks (a Hermite curve with equal tangents passes through the middle of its chord, so a midpoint alone would not
//! show that it bends). [`super::refine`] adds what else lies between where the source needs it.

use glam::{DMat3, DMat4};

use crate::diff::PROBE_FRACTION;
use crate::eval::Evaluation;
use crate::model::{Clip, DEFAULT_FRAME_RATE, Interpolation, MAX_FRAMES, sample_times};

/// How long before a stepped key's jump the value before it is held (as the FBX importer and ufbx's baker do).
pub const STEP_LEAD: f64 = 1e-3;

/// The closest two baked times lie, in seconds: a hundredth of a frame at 24 fps. Blender's importer keys each glTF
/// time on an F-curve, and an F-curve takes two keys within 0.01 frame of each other for one (the second replaces
/// the first), so closer keys would be played with the wrong value at the frame itself.
pub const MIN_KEY_SPACING: f64 = 0.01 / 24.0;

/// The times to bake a clip at first, and which of them are stepped keys.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeTimes {
    /// Sorted and distinct.
    pub times: Vec<f64>,
    /// The times of stepped keys (where a value jumps), sorted.
    pub steps: Vec<f64>,
}

impl BakeTimes {
    /// Per time of `times`: whether a stepped key is at it.
    pub fn step_flags(&self, times: &[f64]) -> Vec<bool> {
        times.iter().map(|&t| self.is_step(t)).collect()
    }

    /// Whether a stepped key is at `time`.
    pub fn is_step(&self, time: f64) -> bool {
        self.steps.binary_search_by(|s| s.total_cmp(&time)).is_ok()
    }
}

/// The times to bake `side` at first.
pub fn bake_times(side: &Evaluation) -> BakeTimes {
    let rate = side.clip.map_or(DEFAULT_FRAME_RATE, Clip::frame_rate);
    let mut keys = side.key_times();
    let (mut steps, mut inside) = (Vec::new(), Vec::new());
    if let (Some(clip), None) = (side.clip, side.layers()) {
        for (times, interpolation) in track_times(clip) {
            match interpolation {
                Interpolation::Step => steps.extend_from_slice(&times[1..]),
                Interpolation::CubicSpline => inside.extend(quarter_points(times)),
                Interpolation::Linear => {}
            }
        }
    }
    let mut source_keys: Vec<f64> = keys.iter().map(|&t| in_single_precision(t)).collect();
    source_keys.sort_by(f64::total_cmp);
    source_keys.dedup();
    keys.extend(steps.iter().map(|t| (t - STEP_LEAD).max(0.0)));
    keys.extend(inside);
    let mut times = sample_times(keys, side.span().start, end(side), rate, MAX_FRAMES).times;
    times.iter_mut().chain(&mut steps).for_each(|t| *t = in_single_precision(*t));
    times.dedup();
    steps.sort_by(f64::total_cmp);
    steps.dedup();
    let times = spaced(times, &steps, &source_keys, |earlier, later| sharper(side, earlier, later));
    steps.retain(|s| times.binary_search_by(|t| t.total_cmp(s)).is_ok());
    BakeTimes { times, steps }
}

/// `times` (sorted) thinned to [`MIN_KEY_SPACING`]. Of two closer times the one that matters more stays: the clip's
/// start and end and stepped keys (jumps, kept where they are; two such times both stay), then the source's keys
/// (where a linear track kinks: a frame between would cut the corner), then frames. Of two keys, the one where the
/// source bends more (`sharper(earlier, later)`: whether it is the later), else the earlier: a file that merges two
/// clocks' samples into one track (at 37 and 37.5 a second, 0.39 ms apart where they meet) may turn at one of them
/// and hold the other on the line between its neighbours; baking that one cuts the turn's corner (by up to its change
/// of velocity times the 0.39 ms). Of two frames, the earlier.
fn spaced(times: Vec<f64>, steps: &[f64], keys: &[f64], sharper: impl Fn(f64, f64) -> bool) -> Vec<f64> {
    let last = times.last().copied();
    let listed = |list: &[f64], t: f64| list.binary_search_by(|s| s.total_cmp(&t)).is_ok();
    let rank = |t: f64| match () {
        _ if Some(t) == last || listed(steps, t) => Rank::Kept,
        _ if listed(keys, t) => Rank::Key,
        _ => Rank::Frame,
    };
    let mut spaced: Vec<f64> = Vec::with_capacity(times.len());
    for t in times {
        let previous_rank =
            if spaced.len() == 1 { Rank::Kept } else { spaced.last().map_or(Rank::Frame, |&p| rank(p)) };
        match spaced.last_mut() {
            Some(previous) if t - *previous < MIN_KEY_SPACING => match (rank(t), previous_rank) {
                (Rank::Kept, Rank::Kept) => spaced.push(t),
                (Rank::Key, Rank::Key) if sharper(*previous, t) => *previous = t,
                (later, earlier) if later > earlier => *previous = t,
                _ => {}
            },
            _ => spaced.push(t),
        }
    }
    spaced
}

/// Whether `side` bends more at `later` than at `earlier`, two times closer than [`MIN_KEY_SPACING`]: how far each
/// pose is from the middle of the poses half their distance before and after it (so that neither window reaches the
/// other time), in model space ([`bend`]).
fn sharper(side: &Evaluation, earlier: f64, later: f64) -> bool {
    let half = 0.5 * (later - earlier);
    let length = PROBE_FRACTION * side.size_of(&[earlier], &side.skeleton().character(), &[]);
    bend(side, later, half, length) > bend(side, earlier, half, length)
}

/// How far `side`'s pose at `time` is from the middle of its poses `half` before and after: where every track is
/// linear across `time` nothing; at a key where a linear track turns, `half` times half its change of velocity. Per
/// bone, the distance bound of [`super::keys::BoneMetric`] (its origin's move, and its axes' times `length`); the
/// largest over the bones.
fn bend(side: &Evaluation, time: f64, half: f64, length: f64) -> f64 {
    let [before, at, after] = [time - half, time, time + half].map(|t| side.pose_at(t).model.model);
    let bones = at.iter().zip(before.iter().zip(&after));
    let off = |(m, (a, b)): (&DMat4, (&DMat4, &DMat4))| {
        let middle = (*a + *b) * 0.5 - *m;
        let frobenius = DMat3::from_mat4(middle).to_cols_array().iter().map(|v| v * v).sum::<f64>().sqrt();
        middle.w_axis.truncate().length() + frobenius * length
    };
    bones.map(off).fold(0.0, f64::max)
}

/// How much a baked time matters when two lie too close ([`spaced`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Rank {
    Frame,
    Key,
    Kept,
}

/// Where sampling ends: the span's end, or for a synced blend's cycle, which wraps to its start at its length, the
/// last `f32` time before it (a player looping the baked clip wraps there too).
fn end(side: &Evaluation) -> f64 {
    let span = side.span();
    let wraps = side.layers().is_some_and(|layers| layers.synced_cycle(side.rig, side.clip).is_some());
    let just_before = f64::from((span.end as f32).next_down());
    if wraps && span.length() > 0.0 { just_before } else { span.end }
}

/// `time` rounded to the nearest `f32`: glTF stores key times in single precision, so a sample taken at exactly such
/// a time is where its key will be (within a step's lead, where the source moves a whole jump in a millisecond, the
/// 1e-8 s a time moves in rounding would otherwise show).
pub fn in_single_precision(time: f64) -> f64 {
    f64::from(time as f32)
}

/// The time array and interpolation of every track of `clip`, morph weights included.
fn track_times(clip: &Clip) -> Vec<(&[f64], Interpolation)> {
    let mut all = Vec::new();
    for tracks in clip.tracks() {
        all.extend(tracks.translation.iter().map(|t| (t.times(), t.interpolation())));
        all.extend(tracks.rotation.iter().map(|t| (t.times(), t.interpolation())));
        all.extend(tracks.scale.iter().map(|t| (t.times(), t.interpolation())));
    }
    for morph in clip.morph() {
        all.extend(morph.weights.iter().map(|t| (t.times(), t.interpolation())));
    }
    all
}

/// The points a quarter, half and three quarters of the way between consecutive times.
fn quarter_points(times: &[f64]) -> impl Iterator<Item = f64> + '_ {
    times.windows(2).flat_map(|w| [0.25, 0.5, 0.75].map(|f| w[0] + (w[1] - w[0]) * f))
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::Vec3;

    use super::*;
    use crate::import::demo_rig;
    use crate::model::{BoneTracks, Track};

    #[test]
    fn cubic_tracks_are_sampled_between_their_keys() {
        let mut rig = demo_rig();
        let times: Arc<[f64]> = vec![0.0, 1.0].into();
        let mut tracks = BoneTracks::new(0);
        let values = vec![Vec3::ZERO, Vec3::ZERO, Vec3::X, Vec3::ZERO, Vec3::Y, Vec3::X];
        tracks.translation = Some(Track::new(times, values, Interpolation::CubicSpline).unwrap());
        rig.clips = vec![Clip::new(0, None, vec![tracks], vec![]).with_frame_rate(1.0)];
        let side = Evaluation::declared(&rig, rig.clips.first());
        assert_eq!(bake_times(&side).times, [0.0, 0.25, 0.5, 0.75, 1.0]);
    }

    #[test]
    fn frames_keys_and_leads() {
        let mut rig = demo_rig();
        let times: Arc<[f64]> = vec![0.0, 0.25, 1.0].into();
        let mut tracks = BoneTracks::new(0);
        tracks.translation = Some(Track::new(times, vec![Vec3::ZERO, Vec3::X, Vec3::Y], Interpolation::Step).unwrap());
        rig.clips = vec![Clip::new(0, None, vec![tracks], vec![]).with_frame_rate(2.0)];
        let side = Evaluation::declared(&rig, rig.clips.first());
        // Frames 0, 0.5, 1; keys 0.25; leads 0.249, 0.999 (in single precision, where glTF keeps them).
        let expected = [0.0, 0.249, 0.25, 0.5, 0.999, 1.0];
        let got = bake_times(&side);
        assert_eq!(got.times.len(), expected.len(), "{got:?}");
        assert!(got.times.iter().zip(expected).all(|(&g, e)| g == in_single_precision(e)), "{got:?}");
        assert_eq!(got.step_flags(&got.times), [false, false, true, false, false, true]);
    }

    #[test]
    fn of_two_keys_closer_than_the_spacing_the_turn_is_baked() {
        // One bone moving along x, then along y, its track keyed at 0, 0.5, 0.5 + 0.3 ms and 1 s: the turn at one of
        // the two close keys, the other on the line between its neighbours (two clocks' samples in one track).
        let close = in_single_precision(0.5 + 3e-4);
        let baked = |turn: f64| {
            let mut rig = demo_rig();
            let at = |t: f64| {
                if t <= turn { Vec3::new(t as f32, 0.0, 0.0) } else { Vec3::new(turn as f32, (t - turn) as f32, 0.0) }
            };
            let times = [0.0, 0.5, close, 1.0];
            let mut tracks = BoneTracks::new(0);
            let values: Vec<Vec3> = times.iter().map(|&t| at(t)).collect();
            tracks.translation = Some(Track::new(Arc::from(times.as_slice()), values, Interpolation::Linear).unwrap());
            rig.clips = vec![Clip::new(0, None, vec![tracks], vec![]).with_frame_rate(2.0)];
            bake_times(&Evaluation::declared(&rig, rig.clips.first())).times
        };
        assert_eq!(baked(close), [0.0, close, 1.0], "the later key turns");
        assert_eq!(baked(0.5), [0.0, 0.5, 1.0], "the earlier key turns");
    }

    #[test]
    fn times_closer_than_a_hundredth_of_a_frame_are_thinned() {
        let close = 0.5 * MIN_KEY_SPACING;
        // Of two frames the earlier stays; a source key just after a frame takes its place, and so does a stepped
        // key; the start and end stay.
        let times = vec![0.0, close, 0.5, 0.5 + close, 1.0 - close, 1.0];
        let earlier = |_, _| false;
        assert_eq!(spaced(times.clone(), &[], &[], earlier), [0.0, 0.5, 1.0]);
        assert_eq!(spaced(times.clone(), &[0.5 + close], &[], earlier), [0.0, 0.5 + close, 1.0]);
        assert_eq!(spaced(times.clone(), &[], &[0.5 + close], earlier), [0.0, 0.5 + close, 1.0]);
        assert_eq!(spaced(times.clone(), &[], &[0.5], earlier), [0.0, 0.5, 1.0], "a key before a frame stays");
        assert_eq!(spaced(vec![0.0, 0.25, 0.5], &[], &[], earlier), [0.0, 0.25, 0.5], "frames apart stay");
        // Of two keys, the one where the source bends more; a frame never displaces a key.
        let keys = [0.5, 0.5 + close];
        assert_eq!(spaced(times.clone(), &[], &keys, earlier), [0.0, 0.5, 1.0]);
        assert_eq!(spaced(times.clone(), &[], &keys, |_, _| true), [0.0, 0.5 + close, 1.0]);
        assert_eq!(spaced(times, &[], &[0.5], |_, _| true), [0.0, 0.5, 1.0]);
    }
}
