//! Animation clips: per-bone keyframe tracks for translation, rotation and scale.
//!
//! Key values are stored in single precision (what every supported file format holds), times in seconds as `f64`
//! and shared between tracks that use the same input, so a long clip of a big rig stays small. Evaluation
//! (`eval::sample`) widens everything to `f64`.

use std::sync::Arc;

use glam::{Quat, Vec3};

use super::{Span, Transform};

/// How values between keys are computed (glTF's sampler interpolations).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Interpolation {
    Step,
    Linear,
    /// Hermite spline; each key stores `[in-tangent, value, out-tangent]`.
    CubicSpline,
}

impl Interpolation {
    /// How many stored values one key has.
    pub fn values_per_key(self) -> usize {
        match self {
            Interpolation::CubicSpline => 3,
            _ => 1,
        }
    }
}

/// Keyframes of one animated property.
#[derive(Clone, Debug, PartialEq)]
pub struct Track<T> {
    times: Arc<[f64]>,
    /// Shared, like the times, by the tracks of channels that read one sampler's output.
    values: Arc<[T]>,
    interpolation: Interpolation,
}

/// Why keyframe data cannot form a track.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackError {
    #[error("no keyframes")]
    Empty,
    #[error("{values} output values for {keys} keys with {interpolation:?} interpolation (expected {expected})")]
    CountMismatch { keys: usize, values: usize, expected: usize, interpolation: Interpolation },
    #[error("key time {index} ({time}) is not finite, or before the previous key")]
    BadTime { index: usize, time: f64 },
    #[error("output value {index} is not finite")]
    NonFinite { index: usize },
    #[error("cubic-spline interpolation needs at least 2 keys")]
    TooFewCubicKeys,
}

/// A key value in single precision whose components can be checked for finiteness.
pub trait KeyValue: Copy + PartialEq {
    fn is_finite(&self) -> bool;
    /// Whether every component is zero (a flat tangent).
    fn is_zero(&self) -> bool;
}

impl KeyValue for Vec3 {
    fn is_finite(&self) -> bool {
        Vec3::is_finite(*self)
    }

    fn is_zero(&self) -> bool {
        *self == Vec3::ZERO
    }
}

impl KeyValue for f32 {
    fn is_finite(&self) -> bool {
        f32::is_finite(*self)
    }

    fn is_zero(&self) -> bool {
        *self == 0.0
    }
}

impl KeyValue for Quat {
    fn is_finite(&self) -> bool {
        Quat::is_finite(*self)
    }

    fn is_zero(&self) -> bool {
        *self == Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)
    }
}

impl<T: KeyValue> Track<T> {
    /// Checks the glTF rules: times finite and increasing (before 0 too: a file's clock may start there); one value per key (three for cubic
    /// splines, at least two keys); every value finite. Keys closer than [`KEY_TIME_RESOLUTION`] (equal times
    /// included, as exporters and zero-filled accessors write them) count once: the last of them holds from that
    /// time on, as a jump does.
    pub fn new(
        times: Arc<[f64]>,
        values: impl Into<Arc<[T]>>,
        interpolation: Interpolation,
    ) -> Result<Self, TrackError> {
        let values = values.into();
        if times.is_empty() {
            return Err(TrackError::Empty);
        }
        let expected = times.len() * interpolation.values_per_key();
        if values.len() != expected {
            return Err(TrackError::CountMismatch { keys: times.len(), values: values.len(), expected, interpolation });
        }
        if let Some(index) = first_bad_time(&times) {
            return Err(TrackError::BadTime { index, time: times[index] });
        }
        // Folded without stopping (vectorised, and every key is read anyway when all are good); searched on failure.
        if !values.iter().fold(true, |finite, v| finite & v.is_finite()) {
            let index = values.iter().position(|v| !v.is_finite()).unwrap_or_default();
            return Err(TrackError::NonFinite { index });
        }
        let (times, values) = merge_close_keys(times, values, interpolation.values_per_key());
        if interpolation == Interpolation::CubicSpline && times.len() < 2 {
            return Err(TrackError::TooFewCubicKeys);
        }
        Ok(Track { times, values, interpolation })
    }

    /// Whether the track holds one value throughout: all keys equal and, for cubic splines, all tangents flat.
    /// (Sampled between keys such a track may still differ from its key by rounding.)
    pub fn is_constant(&self) -> bool {
        let per_key = self.interpolation.values_per_key();
        let first = self.values[per_key / 2];
        self.values
            .chunks(per_key)
            .all(|key| key.iter().enumerate().all(|(i, v)| if i == per_key / 2 { *v == first } else { v.is_zero() }))
    }

    /// The one value a constant track holds ([`Track::is_constant`]).
    pub fn held(&self) -> Option<T> {
        self.is_constant().then(|| self.values[self.interpolation.values_per_key() / 2])
    }
}

impl<T> Track<T> {
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The stored values (`3 × keys` for cubic splines: in-tangent, value, out-tangent per key).
    pub fn values(&self) -> &[T] {
        &self.values
    }

    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    pub fn last_time(&self) -> f64 {
        self.times[self.times.len() - 1]
    }
}

/// Frames per second assumed for a clip whose keys show no rate.
pub const DEFAULT_FRAME_RATE: f64 = 30.0;

/// The frame rate the key times show, for a format that states none: the slowest rate whose frames every key lands
/// on ([`grid_rate`]), else the most common spacing between keys ([`spacing_rate`]).
fn key_rate(arrays: Vec<&[f64]>) -> Option<f64> {
    grid_rate(&arrays).or_else(|| spacing_rate(&arrays))
}

/// Frame rates animation is commonly authored at, tried first, slowest first: keys at whole seconds are at 24 fps,
/// not 1, and keys every other frame of 60 fps at 30, not 15 (any rate whose frames hold every key is right about
/// the keys; a standard one is also likely the scene's).
const STANDARD_RATES: [f64; 9] = [24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 100.0, 120.0, 240.0];

/// The fastest rate tried for a grid; finer key times are read by their spacing.
const MAX_GRID_RATE: u32 = 240;

/// The slowest frame rate, standard ones first, then every whole rate up to [`MAX_GRID_RATE`] fps, on whose frames
/// every key time lies (within single precision); `None` when no rate fits, or when every key sits at t = 0 (any
/// rate would). An exporter that keys only some frames (Blender's cubic splines: every 15th) still shows its rate,
/// where the spacing of the keys would show 2 fps.
fn grid_rate(arrays: &[&[f64]]) -> Option<f64> {
    let times = || arrays.iter().flat_map(|times| times.iter().copied());
    if !times().any(|t| t > 0.0) {
        return None;
    }
    let whole_rates = (1..=MAX_GRID_RATE).map(f64::from);
    STANDARD_RATES.into_iter().chain(whole_rates).find(|&rate| times().all(|t| on_frame(t, rate)))
}

/// Whether `time` is a whole frame at `rate`, within the rounding of a single-precision time (half a unit in the
/// last place, so `2⁻²⁴ · time` seconds; four times that allowed).
fn on_frame(time: f64, rate: f64) -> bool {
    let frame = time * rate;
    (frame - frame.round()).abs() <= 2.0 * f64::from(f32::EPSILON) * frame.abs()
}

/// The rate of the most common spacing between consecutive key times of each array, rounded to 1/1000 fps (at least
/// a quarter of the spacings, and at least two, must agree, so scattered keys give none): 29.97 for keys 1001/30000 s
/// apart, even with some keys missing.
fn spacing_rate(arrays: &[&[f64]]) -> Option<f64> {
    let mut counts: std::collections::BTreeMap<u64, usize> = std::collections::BTreeMap::new();
    let mut total = 0;
    for gap in arrays.iter().flat_map(|times| times.windows(2)).map(|w| w[1] - w[0]).filter(|&gap| gap > 1e-6) {
        *counts.entry((1000.0 / gap).round() as u64).or_default() += 1;
        total += 1;
    }
    let (&rate, &count) = counts.iter().max_by_key(|(rate, count)| (**count, std::cmp::Reverse(**rate)))?;
    (count >= 2 && count * 4 >= total && rate > 0).then(|| rate as f64 / 1000.0)
}

/// The first time that is not finite, or before the one before it.
fn first_bad_time(times: &[f64]) -> Option<usize> {
    // Folded without stopping, as the values are (the same array is checked for every track that shares it).
    let finite = times.iter().fold(true, |finite, t| finite & t.is_finite());
    let sorted = times.windows(2).fold(true, |sorted, w| sorted & (w[0] <= w[1]));
    if finite && sorted {
        return None;
    }
    let mut previous = f64::NEG_INFINITY;
    times.iter().position(|&time| {
        let bad = !time.is_finite() || time < previous;
        previous = time;
        bad
    })
}

/// Key times closer than this are one key: one FBX tick (1/46,186,158,000 s), the finest time any supported
/// format stores.
pub const KEY_TIME_RESOLUTION: f64 = 1.0 / 46_186_158_000.0;

/// Sorted `times` and their keys (`per_key` values each) with each run of keys closer than
/// [`KEY_TIME_RESOLUTION`] to the previous one reduced to its last key; the inputs themselves when there is none.
fn merge_close_keys<T: Copy>(times: Arc<[f64]>, values: Arc<[T]>, per_key: usize) -> (Arc<[f64]>, Arc<[T]>) {
    let close = |w: &[f64]| w[1] - w[0] < KEY_TIME_RESOLUTION;
    if !times.windows(2).fold(false, |any, w| any | close(w)) {
        return (times, values);
    }
    let keep = |k: usize| times.get(k + 1).is_none_or(|next| next - times[k] >= KEY_TIME_RESOLUTION);
    let kept: Vec<usize> = (0..times.len()).filter(|&k| keep(k)).collect();
    let merged_times = kept.iter().map(|&k| times[k]).collect();
    let merged_values = kept.iter().flat_map(|&k| values[k * per_key..(k + 1) * per_key].iter().copied()).collect();
    (merged_times, merged_values)
}

/// The animated properties of one bone in a clip.
#[derive(Clone, Debug, PartialEq)]
pub struct BoneTracks {
    pub bone: usize,
    pub translation: Option<Track<Vec3>>,
    pub rotation: Option<Track<Quat>>,
    pub scale: Option<Track<Vec3>>,
    /// The stretch rotation `U` of the local transform while the clip plays, where the clip sets it: a format whose
    /// animation gives a whole local transform (UsdSkel's translations, rotations and scales: one identity key; a
    /// pose dump's matrices, which may shear: one key per sample, its frame kept continuous so that it slerps);
    /// the rest's where `None`. The scale track's factors apply in this frame.
    pub stretch: Option<Track<Quat>>,
}

impl BoneTracks {
    pub fn new(bone: usize) -> Self {
        BoneTracks { bone, translation: None, rotation: None, scale: None, stretch: None }
    }

    /// The transform the bone holds throughout when every track holds one value (`rest` where it has no track).
    pub fn held(&self, rest: &Transform) -> Option<Transform> {
        let mut held = *rest;
        if let Some(track) = &self.translation {
            held.translation = track.held()?.as_dvec3();
        }
        if let Some(track) = &self.rotation {
            held.rotation = track.held()?.as_dquat().normalize();
        }
        if let Some(track) = &self.scale {
            held.scale = track.held()?.as_dvec3();
        }
        if let Some(track) = &self.stretch {
            held.stretch = track.held()?.as_dquat().normalize();
        }
        Some(held)
    }

    /// The time arrays of the animated properties (each sorted; possibly the same array more than once).
    fn time_arrays(&self) -> impl Iterator<Item = &[f64]> {
        let t = self.translation.iter().map(Track::times);
        let r = self.rotation.iter().map(Track::times);
        let s = self.scale.iter().map(Track::times);
        let u = self.stretch.iter().map(Track::times);
        t.chain(r).chain(s).chain(u)
    }
}

/// The animated morph-target weights of the meshes on one bone: one track per target (glTF's `weights` of a node,
/// FBX's blend-shape weights), sharing their times.
#[derive(Clone, Debug, PartialEq)]
pub struct MorphWeights {
    pub bone: usize,
    pub weights: Vec<Track<f32>>,
}

impl MorphWeights {
    fn time_arrays(&self) -> impl Iterator<Item = &[f64]> {
        self.weights.iter().map(Track::times)
    }
}

/// One animation.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// Index among the file's animations.
    pub index: usize,
    pub name: Option<String>,
    /// Tracks sorted by bone, at most one entry per bone.
    tracks: Vec<BoneTracks>,
    /// Sorted by bone, at most one entry per bone.
    morph: Vec<MorphWeights>,
    span: Span,
    /// Frames per second: the rate the file states (FBX, BVH), else the rate its key times show (see
    /// [`Clip::frame_rate`]).
    frame_rate: Option<f64>,
}

impl Clip {
    /// Sorts the tracks and morph weights by bone; the clip spans its keys, from the first key time of any track to
    /// the last (a glTF animation has no span of its own: its keys are where it plays), at t = 0 without keys.
    pub fn new(index: usize, name: Option<String>, mut tracks: Vec<BoneTracks>, mut morph: Vec<MorphWeights>) -> Self {
        tracks.sort_by_key(|t| t.bone);
        morph.sort_by_key(|m| m.bone);
        let arrays =
            tracks.iter().flat_map(BoneTracks::time_arrays).chain(morph.iter().flat_map(MorphWeights::time_arrays));
        let (first, last) = arrays
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(first, last), t| (first.min(t[0]), last.max(t[t.len() - 1])));
        let span = if first <= last { Span::new(first, last) } else { Span::at(0.0) };
        Clip { index, name, tracks, morph, span, frame_rate: None }
    }

    /// The clip over `span`, the stretch of the file's clock its format says it plays (an FBX take's start and stop,
    /// a USD stage's start and end time codes) rather than its keys'.
    pub fn with_span(mut self, span: Span) -> Self {
        self.span = span;
        self
    }

    /// The clip with the rate its key times show as its frame rate, for a format that states none (glTF): the
    /// slowest (standard first) rate on whose frames every key lies, so a file exported at 24 fps reads as 24 fps
    /// however few of its frames are keyed; else the rate of the most common spacing between keys.
    pub fn with_key_rate(mut self) -> Self {
        self.frame_rate = key_rate(self.time_arrays());
        self
    }

    /// The clip with the frame rate its file states (finite and positive, else the key spacing's stays).
    pub fn with_frame_rate(mut self, rate: f64) -> Self {
        if rate.is_finite() && rate > 0.0 {
            self.frame_rate = Some(rate);
        }
        self
    }

    /// Frames per second of the clip: the file's own rate where it states one (FBX, BVH), else the rate its key
    /// times show where the importer measured it ([`Clip::with_key_rate`]), else 30.
    pub fn frame_rate(&self) -> f64 {
        self.frame_rate.unwrap_or(DEFAULT_FRAME_RATE)
    }

    pub fn tracks(&self) -> &[BoneTracks] {
        &self.tracks
    }

    /// How many channels the clip keys: translations, rotations and scales of bones, and morph weights.
    pub fn channels(&self) -> usize {
        let bones = self.tracks.iter().map(|t| {
            usize::from(t.translation.is_some()) + usize::from(t.rotation.is_some()) + usize::from(t.scale.is_some())
        });
        bones.sum::<usize>() + self.morph.iter().map(|m| m.weights.len()).sum::<usize>()
    }

    /// The animated morph weights, by bone.
    pub fn morph(&self) -> &[MorphWeights] {
        &self.morph
    }

    /// Where the clip lies on its file's clock.
    pub fn span(&self) -> Span {
        self.span
    }

    /// A name for people: the clip's name, or `animation <index>`.
    pub fn label(&self) -> String {
        self.name.clone().unwrap_or_else(|| format!("animation {}", self.index))
    }

    /// Every key time of every track, sorted, without duplicates.
    ///
    /// Tracks that read the same input share one time array (a glTF sampler input, or one array for a whole clip),
    /// and each array is sorted already: only the distinct arrays are merged, and one alone is the answer as is.
    pub fn key_times(&self) -> Vec<f64> {
        let arrays = self.time_arrays();
        if let [only] = arrays[..] {
            return only.to_vec();
        }
        let mut times = arrays.concat();
        times.sort_unstable_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// The distinct time arrays of the tracks (tracks that read the same input share one).
    fn time_arrays(&self) -> Vec<&[f64]> {
        let mut arrays: Vec<&[f64]> = Vec::new();
        for times in self.tracks.iter().flat_map(BoneTracks::time_arrays) {
            if !arrays.iter().any(|seen| std::ptr::eq(*seen, times)) {
                arrays.push(times);
            }
        }
        arrays
    }

    /// The tracks of one bone, if the clip animates it.
    pub fn tracks_of(&self, bone: usize) -> Option<&BoneTracks> {
        self.tracks.binary_search_by_key(&bone, |t| t.bone).ok().map(|i| &self.tracks[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clip whose one track has keys at `times` (rounded to single precision, as glTF stores them), its rate read
    /// from them.
    fn keyed_at(times: impl IntoIterator<Item = f64>) -> Clip {
        let times: Vec<f64> = times.into_iter().map(|t| f64::from(t as f32)).collect();
        let n = times.len();
        let mut tracks = BoneTracks::new(0);
        tracks.translation = Some(Track::new(times.into(), vec![Vec3::ZERO; n], Interpolation::Linear).unwrap());
        Clip::new(0, None, vec![tracks], vec![]).with_key_rate()
    }

    #[test]
    fn the_frame_rate_is_the_files_or_the_key_times() {
        // Keys 1/24 s apart with one missing: 24 fps.
        let mut times: Vec<f64> = (0..48).map(|k| f64::from(k) / 24.0).collect();
        times.remove(7);
        assert_eq!(keyed_at(times.clone()).frame_rate(), 24.0);
        // Blender's cubic splines key every 15th frame of 30 fps from frame 1: spaced 0.5 s, but at 30 fps.
        assert_eq!(keyed_at((0..5).map(|k| f64::from(1 + 15 * k) / 30.0)).frame_rate(), 30.0);
        // Every other frame of 60 fps lies on 30 fps's frames, the slower standard rate; every third (k/20 s) on
        // none of 24's, 25's, 30's, 48's or 50's.
        assert_eq!(keyed_at((0..30).map(|k| f64::from(2 * k) / 60.0)).frame_rate(), 30.0);
        assert_eq!(keyed_at((0..30).map(|k| f64::from(3 * k) / 60.0)).frame_rate(), 60.0);
        // Frames no standard rate holds: the slowest whole rate that does (7 fps), else the spacing (NTSC 29.97,
        // rounded to 1/1000 fps, whose frames no whole rate up to 240 holds).
        assert_eq!(keyed_at((0..20).map(|k| f64::from(k) / 7.0)).frame_rate(), 7.0);
        assert_eq!(keyed_at((0..60).map(|k| f64::from(k) * 1001.0 / 30000.0)).frame_rate(), 29.97);
        // Scattered keys: no rate, 30 assumed; keys only at 0 show none either; a stated rate wins over the keys.
        assert_eq!(keyed_at([0.0, 0.314159, 0.35, 1.1, 1.7]).frame_rate(), DEFAULT_FRAME_RATE);
        assert_eq!(keyed_at([0.0]).frame_rate(), DEFAULT_FRAME_RATE);
        assert_eq!(keyed_at(times).with_frame_rate(120.0).frame_rate(), 120.0);
        assert_eq!(keyed_at([0.0]).with_frame_rate(f64::NAN).frame_rate(), DEFAULT_FRAME_RATE);
    }

    #[test]
    fn a_frame_is_whole_within_single_precision() {
        // 1/30 s is 0.033333335 in f32: 1.00000004 frames, on the frame; a tenth of a millisecond off is not.
        assert!(on_frame(f64::from(1.0f32 / 30.0), 30.0));
        assert!(!on_frame(1.0 / 30.0 + 1e-4, 30.0));
        // An hour in: f32 times are 1/4096 s apart, still within the tolerance of whole frames at 24 fps.
        assert!(on_frame(f64::from((86_399.0f64 / 24.0) as f32), 24.0));
        assert!(!on_frame(3600.0 + 0.5 / 24.0, 24.0));
    }

    /// The slowest standard rate whose frames hold the frames `frames` of `rate`: frame k at rate r is frame k·r'/r
    /// at r', whole for every k exactly when r'·gcd(k) is a multiple of r. Exact integer arithmetic on frame
    /// numbers, independent of the floating-point test on times.
    fn slowest_standard_rate_holding(rate: u64, frames: &[u64]) -> Option<f64> {
        let gcd = frames.iter().fold(0, |g, &k| num_gcd(g, k));
        STANDARD_RATES.into_iter().find(|&other| (other as u64 * gcd).is_multiple_of(rate))
    }

    fn num_gcd(a: u64, b: u64) -> u64 {
        if b == 0 { a } else { num_gcd(b, a % b) }
    }

    proptest::proptest! {
        /// Any subset of a standard rate's frames (over a minute, as single-precision times) reads as the slowest
        /// standard rate on whose frames they all lie: the rate itself when two keys are one frame apart, else a
        /// rate its frames lie on too (24 for every other frame of 48), by the exact arithmetic above.
        #[test]
        fn a_subset_of_a_standard_rates_frames_reads_as_the_slowest_rate_holding_them(
            rate in proptest::sample::select(STANDARD_RATES.to_vec()),
            frames in proptest::collection::btree_set(0u64..4000, 2..40),
        ) {
            let frames: Vec<u64> = frames.into_iter().collect();
            let clip = keyed_at(frames.iter().map(|&k| k as f64 / rate));
            let expected = slowest_standard_rate_holding(rate as u64, &frames);
            proptest::prop_assert!(expected.is_some(), "the rate itself holds them");
            proptest::prop_assert_eq!(clip.frame_rate(), expected.unwrap_or_default());
            if frames.windows(2).any(|w| w[1] - w[0] == 1) {
                proptest::prop_assert_eq!(clip.frame_rate(), rate);
            }
        }
    }

    fn times(t: &[f64]) -> Arc<[f64]> {
        t.into()
    }

    #[test]
    fn constant_tracks() {
        let (one, two) = (Vec3::ONE, Vec3::new(1.0, 2.0, 1.0));
        let track = |values: Vec<Vec3>, interpolation| Track::new(times(&[0.0, 1.0]), values, interpolation).unwrap();
        assert!(track(vec![one, one], Interpolation::Linear).is_constant());
        assert!(!track(vec![one, two], Interpolation::Step).is_constant());
        assert!(Track::new(times(&[0.5]), vec![two], Interpolation::Linear).unwrap().is_constant());
        // Cubic splines: equal values are not enough, the tangents must be flat too.
        let z = Vec3::ZERO;
        assert!(track(vec![z, one, z, z, one, z], Interpolation::CubicSpline).is_constant());
        assert!(!track(vec![z, one, two, z, one, z], Interpolation::CubicSpline).is_constant());
    }

    #[test]
    fn track_validation() {
        let v = vec![Vec3::ZERO; 2];
        assert!(Track::new(times(&[0.0, 1.0]), v.clone(), Interpolation::Linear).is_ok());
        assert_eq!(Track::<Vec3>::new(times(&[]), vec![], Interpolation::Step), Err(TrackError::Empty));
        assert!(matches!(
            Track::new(times(&[0.0, 1.0]), v.clone(), Interpolation::CubicSpline),
            Err(TrackError::CountMismatch { expected: 6, .. })
        ));
        assert!(matches!(
            Track::new(times(&[1.0, 0.5]), v.clone(), Interpolation::Linear),
            Err(TrackError::BadTime { index: 1, .. })
        ));
        assert!(Track::new(times(&[-1.0, 0.5]), v.clone(), Interpolation::Linear).is_ok(), "a clock before 0");
        assert!(matches!(
            Track::new(times(&[0.0, f64::NAN]), v.clone(), Interpolation::Linear),
            Err(TrackError::BadTime { index: 1, .. })
        ));
        assert_eq!(
            Track::new(times(&[0.0, 1.0]), vec![Vec3::ZERO, Vec3::NAN], Interpolation::Linear),
            Err(TrackError::NonFinite { index: 1 })
        );
        assert_eq!(
            Track::new(times(&[0.0]), vec![Vec3::ZERO; 3], Interpolation::CubicSpline),
            Err(TrackError::TooFewCubicKeys)
        );
    }

    #[test]
    fn keys_closer_than_a_tick_count_once_the_last_holding() {
        let (a, b, c) = (Vec3::X, Vec3::Y, Vec3::Z);
        let track = Track::new(times(&[0.0, 0.0, 1.0, 1.0 + 1e-12]), vec![a, b, c, a], Interpolation::Linear).unwrap();
        assert_eq!(track.times(), &[0.0, 1.0 + 1e-12]);
        assert_eq!(track.values(), &[b, a]);
        let cubic = |v: Vec3| [Vec3::ZERO, v, Vec3::ZERO];
        let values = [cubic(a), cubic(b), cubic(c)].concat();
        let track = Track::new(times(&[0.0, 0.5, 0.5]), values, Interpolation::CubicSpline).unwrap();
        assert_eq!(track.values(), &[cubic(a), cubic(c)].concat());
        let shared = times(&[0.0, 1.0]);
        let track = Track::new(shared.clone(), vec![a, b], Interpolation::Step).unwrap();
        assert!(Arc::ptr_eq(&track.times, &shared), "times without close keys stay shared");
        assert_eq!(
            Track::new(times(&[0.0, 0.0]), vec![Vec3::ZERO; 6], Interpolation::CubicSpline),
            Err(TrackError::TooFewCubicKeys),
            "one key left"
        );
    }

    #[test]
    fn span_and_key_times_cover_all_tracks() {
        let mut a = BoneTracks::new(3);
        a.translation = Some(Track::new(times(&[0.5, 2.0]), vec![Vec3::ZERO; 2], Interpolation::Linear).unwrap());
        let mut b = BoneTracks::new(1);
        b.rotation = Some(Track::new(times(&[0.25, 0.5, 1.0]), vec![Quat::IDENTITY; 3], Interpolation::Step).unwrap());
        let weights = vec![Track::new(times(&[-0.5, 0.0]), vec![0.0f32; 2], Interpolation::Linear).unwrap()];
        let clip = Clip::new(0, None, vec![a.clone(), b.clone()], vec![]);
        assert_eq!(clip.span(), Span::new(0.25, 2.0), "from the first key to the last, not from 0");
        let morphed = Clip::new(0, None, vec![a, b], vec![MorphWeights { bone: 0, weights }]);
        assert_eq!(morphed.span(), Span::new(-0.5, 2.0), "morph weights count, before 0 too");
        assert_eq!(Clip::new(0, None, vec![], vec![]).span(), Span::at(0.0));
        assert_eq!(clip.key_times(), vec![0.25, 0.5, 1.0, 2.0]);
        assert_eq!(clip.tracks()[0].bone, 1, "tracks are sorted by bone");
        assert!(clip.tracks_of(3).is_some() && clip.tracks_of(2).is_none());
        assert_eq!(clip.label(), "animation 0");
    }

    #[test]
    fn key_times_merge_shared_and_distinct_arrays() {
        let shared = times(&[0.0, 1.0, 2.0]);
        let mut tracks: Vec<BoneTracks> = (0..3)
            .map(|bone| {
                let mut t = BoneTracks::new(bone);
                t.rotation = Some(Track::new(shared.clone(), vec![Quat::IDENTITY; 3], Interpolation::Linear).unwrap());
                t.translation = Some(Track::new(shared.clone(), vec![Vec3::ZERO; 3], Interpolation::Step).unwrap());
                t
            })
            .collect();
        let one_array = Clip::new(0, None, tracks.clone(), vec![]);
        assert_eq!(one_array.key_times(), vec![0.0, 1.0, 2.0]);
        tracks[1].scale = Some(Track::new(times(&[0.5, 1.0, 2.5]), vec![Vec3::ONE; 3], Interpolation::Linear).unwrap());
        let two_arrays = Clip::new(0, None, tracks, vec![]);
        assert_eq!(two_arrays.key_times(), vec![0.0, 0.5, 1.0, 2.0, 2.5]);
        assert_eq!(two_arrays.span(), Span::new(0.0, 2.5));
    }
}
