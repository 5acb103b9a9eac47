//! Sampling a clip at a time, exactly as glTF's Appendix C writes it.
//!
//! Outside a track's key range the value is clamped to the nearest end; at a key time the key value is used as is;
//! between keys `t = (t_c − t_k)/(t_{k+1} − t_k)` and STEP takes `v_k`, LINEAR interpolates linearly (rotations by
//! shortest-path slerp), CUBICSPLINE evaluates the Hermite spline with tangents scaled by the key interval
//! (rotations then normalised). Bones the clip does not animate keep their rest transform.

use glam::{DQuat, DVec3, Quat, Vec3};

use crate::math::slerp;
use crate::model::{Clip, Interpolation, Skeleton, Track, Transform};

/// A key value type and how it interpolates, in double precision.
pub trait Interpolate: Copy {
    type Wide: Copy;
    /// The stored number in double precision (tangents are used as they are).
    fn widen(self) -> Self::Wide;
    /// A key's value in double precision, made valid for its kind.
    fn value(self) -> Self::Wide {
        self.widen()
    }
    fn linear(a: Self::Wide, b: Self::Wide, t: f64) -> Self::Wide;
    /// Hermite basis weights `(h00, h10, h01, h11)` applied to `(v0, b0, v1, a1)`, tangents already scaled.
    fn hermite(v0: Self::Wide, b0: Self::Wide, v1: Self::Wide, a1: Self::Wide, h: [f64; 4]) -> Self::Wide;
}

impl Interpolate for Vec3 {
    type Wide = DVec3;

    fn widen(self) -> DVec3 {
        self.as_dvec3()
    }

    fn linear(a: DVec3, b: DVec3, t: f64) -> DVec3 {
        a * (1.0 - t) + b * t
    }

    fn hermite(v0: DVec3, b0: DVec3, v1: DVec3, a1: DVec3, h: [f64; 4]) -> DVec3 {
        v0 * h[0] + b0 * h[1] + v1 * h[2] + a1 * h[3]
    }
}

impl Interpolate for f32 {
    type Wide = f64;

    fn widen(self) -> f64 {
        f64::from(self)
    }

    fn linear(a: f64, b: f64, t: f64) -> f64 {
        a * (1.0 - t) + b * t
    }

    fn hermite(v0: f64, b0: f64, v1: f64, a1: f64, h: [f64; 4]) -> f64 {
        v0 * h[0] + b0 * h[1] + v1 * h[2] + a1 * h[3]
    }
}

impl Interpolate for Quat {
    type Wide = DQuat;

    fn widen(self) -> DQuat {
        self.as_dquat()
    }

    /// Normalised, as engines do: exporters often write rotation keys with few digits (SimpleSkin's
    /// `0.707, 0.707` is 0.03 % too long), and a non-unit quaternion would read as scale. Zero stays the identity.
    fn value(self) -> DQuat {
        let q = self.as_dquat();
        let length = q.length();
        if length > 0.0 { q / length } else { DQuat::IDENTITY }
    }

    fn linear(a: DQuat, b: DQuat, t: f64) -> DQuat {
        slerp(a, b, t)
    }

    fn hermite(v0: DQuat, b0: DQuat, v1: DQuat, a1: DQuat, h: [f64; 4]) -> DQuat {
        let q = v0 * h[0] + b0 * h[1] + v1 * h[2] + a1 * h[3];
        // The spec requires the result normalised; a zero result (v1 = −v0 at the midpoint) keeps v0.
        if q.length_squared() > 0.0 { q.normalize() } else { v0 }
    }
}

/// Where a time falls among a track's keys.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Span {
    /// At key `k`, or clamped to it (before the first key, after the last, or NaN).
    Key(usize),
    /// `times[k] < time < times[k + 1]`, at fraction `t` of the way.
    Between { k: usize, t: f64 },
}

impl Span {
    /// Where `time` falls in `times` (non-empty and strictly increasing, as [`Track`] guarantees), looking first at
    /// segment `*hint` and the one after it (where a slightly earlier time fell), then searching; `*hint` becomes
    /// the segment found. Increasing times, as a whole-clip scan visits them, then cost a comparison or two instead
    /// of a binary search; any hint gives the same answer.
    #[inline]
    pub(crate) fn locate_near(times: &[f64], time: f64, hint: &mut usize) -> Span {
        let last = times.len() - 1;
        if time.is_nan() || time <= times[0] {
            return Span::Key(0);
        }
        if time >= times[last] {
            return Span::Key(last);
        }
        // times[k] ≤ time < times[k + 1]
        let within = |k: usize| k < last && times[k] <= time && time < times[k + 1];
        let k = [*hint, *hint + 1].into_iter().find(|&k| within(k));
        let k = k.unwrap_or_else(|| times.partition_point(|&t| t <= time) - 1);
        *hint = k;
        if times[k] == time {
            return Span::Key(k);
        }
        Span::Between { k, t: (time - times[k]) / (times[k + 1] - times[k]) }
    }
}

/// The value of key `k` (for cubic splines, key `k` stores `[a_k, v_k, b_k]`).
pub(crate) fn key_value<T: Interpolate>(track: &Track<T>, k: usize) -> T::Wide {
    let per_key = track.interpolation().values_per_key();
    track.values()[k * per_key + per_key / 2].value()
}

/// The track's value at `time` (seconds).
pub fn sample_track<T: Interpolate>(track: &Track<T>, time: f64) -> T::Wide {
    sample_track_near(track, time, &mut 0)
}

/// [`sample_track`], the key search starting at `*hint` (see [`Span::locate_near`]).
pub(crate) fn sample_track_near<T: Interpolate>(track: &Track<T>, time: f64, hint: &mut usize) -> T::Wide {
    let value = |k: usize| key_value(track, k);
    let (k, t) = match Span::locate_near(track.times(), time, hint) {
        Span::Key(k) => return value(k),
        Span::Between { k, t } => (k, t),
    };
    let times = track.times();
    let span = times[k + 1] - times[k];
    match track.interpolation() {
        Interpolation::Step => value(k),
        Interpolation::Linear => T::linear(value(k), value(k + 1), t),
        Interpolation::CubicSpline => {
            let out_tangent = track.values()[3 * k + 2].widen();
            let in_tangent = track.values()[3 * (k + 1)].widen();
            let [h00, h10, h01, h11] = hermite_basis(t);
            T::hermite(value(k), out_tangent, value(k + 1), in_tangent, [h00, span * h10, h01, span * h11])
        }
    }
}

/// The cubic Hermite basis `(h00, h10, h01, h11)` at `t` in `[0, 1]`, tangents not yet scaled by the key interval.
pub(crate) fn hermite_basis(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [2.0 * t3 - 3.0 * t2 + 1.0, t3 - 2.0 * t2 + t, -2.0 * t3 + 3.0 * t2, t3 - t2]
}

/// Writes the rest pose of every bone into `pose`.
pub(crate) fn rest_pose_into(skeleton: &Skeleton, pose: &mut Vec<Transform>) {
    pose.clear();
    pose.extend(skeleton.bones().iter().map(|b| b.rest));
}

/// How each kind of track is read at a time: as authored ([`sample_track`]), or resampled by a layer. `hint` is
/// where the track's key search starts (see [`Span::locate_near`]).
pub(crate) trait TrackSampler {
    fn vector(&self, track: &Track<Vec3>, time: f64, hint: &mut usize) -> DVec3;
    fn rotation(&self, track: &Track<Quat>, time: f64, hint: &mut usize) -> DQuat;
}

/// Every track as its file says.
struct Authored;

impl TrackSampler for Authored {
    fn vector(&self, track: &Track<Vec3>, time: f64, hint: &mut usize) -> DVec3 {
        sample_track_near(track, time, hint)
    }

    fn rotation(&self, track: &Track<Quat>, time: f64, hint: &mut usize) -> DQuat {
        sample_track_near(track, time, hint)
    }
}

/// Writes the local pose of every bone at `time` into `pose` (resized to the skeleton).
pub fn sample_clip(skeleton: &Skeleton, clip: &Clip, time: f64, pose: &mut Vec<Transform>) {
    sample_clip_with(skeleton, clip, time, &Authored, pose, None);
}

/// [`sample_clip`] keeping in `hints` (when given) where each track's keys were found, so that sampling the same
/// clip at a slightly later time next skips the key searches (a whole-clip scan walks its times in order).
pub(crate) fn sample_clip_near(
    skeleton: &Skeleton,
    clip: &Clip,
    time: f64,
    pose: &mut Vec<Transform>,
    hints: Option<&mut Vec<usize>>,
) {
    sample_clip_with(skeleton, clip, time, &Authored, pose, hints);
}

/// [`sample_clip`] with each track read by `sampler`, and with key hints (four per bone's tracks) when given.
pub(crate) fn sample_clip_with(
    skeleton: &Skeleton,
    clip: &Clip,
    time: f64,
    sampler: &impl TrackSampler,
    pose: &mut Vec<Transform>,
    mut hints: Option<&mut Vec<usize>>,
) {
    rest_pose_into(skeleton, pose);
    if let Some(hints) = &mut hints {
        hints.resize(4 * clip.tracks().len(), 0);
    }
    for (i, tracks) in clip.tracks().iter().enumerate() {
        let Some(local) = pose.get_mut(tracks.bone) else {
            continue;
        };
        let mut fresh = [0; 4];
        let hint = hints.as_deref_mut().map_or(&mut fresh[..], |h| &mut h[4 * i..4 * i + 4]);
        if let Some(track) = &tracks.translation {
            local.translation = sampler.vector(track, time, &mut hint[0]);
        }
        if let Some(track) = &tracks.rotation {
            local.rotation = sampler.rotation(track, time, &mut hint[1]);
        }
        if let Some(track) = &tracks.scale {
            local.scale = sampler.vector(track, time, &mut hint[2]);
        }
        if let Some(track) = &tracks.stretch {
            local.stretch = sampler.rotation(track, time, &mut hint[3]);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;

    fn vec_track(times: &[f64], values: &[[f32; 3]], interpolation: Interpolation) -> Track<Vec3> {
        Track::new(Arc::from(times), values.iter().map(|&v| Vec3::from(v)).collect::<Arc<[_]>>(), interpolation)
            .unwrap()
    }

    #[test]
    fn a_key_hint_never_changes_the_value() {
        let times: Vec<f64> = (0..50).map(|k| f64::from(k) * 0.1 + 0.03 * f64::from(k % 3)).collect();
        let values: Vec<[f32; 3]> = (0..50).map(|k| [k as f32, (k * k) as f32, -(k as f32)]).collect();
        for interpolation in [Interpolation::Step, Interpolation::Linear] {
            let track = vec_track(&times, &values, interpolation);
            // Forward in small steps (the scan's order), then jumps back and past the ends: every hint must end
            // where a fresh search ends.
            let mut queries: Vec<f64> = (0..700).map(|i| f64::from(i) * 0.01 - 0.5).collect();
            queries.extend([3.3, 0.2, 6.0, -1.0, f64::NAN, 2.45, 2.45, times[17]]);
            let mut hint = 0;
            for &time in &queries {
                let fresh = sample_track(&track, time);
                let near = sample_track_near(&track, time, &mut hint);
                assert!(fresh == near || (fresh.is_nan() && near.is_nan()), "{interpolation:?} at {time}");
                assert!(hint < times.len(), "hint {hint} out of range");
            }
        }
    }

    #[test]
    fn step_and_linear_at_keys_between_and_outside() {
        let values = [[0.0, 0.0, 0.0], [2.0, 4.0, -2.0], [2.0, 0.0, 0.0]];
        let step = vec_track(&[1.0, 2.0, 4.0], &values, Interpolation::Step);
        let linear = vec_track(&[1.0, 2.0, 4.0], &values, Interpolation::Linear);
        // Before the first key and after the last: clamped.
        assert_eq!(sample_track(&linear, 0.0), DVec3::ZERO);
        assert_eq!(sample_track(&linear, 9.0), DVec3::new(2.0, 0.0, 0.0));
        // At a key: the key value.
        assert_eq!(sample_track(&linear, 2.0), DVec3::new(2.0, 4.0, -2.0));
        assert_eq!(sample_track(&step, 2.0), DVec3::new(2.0, 4.0, -2.0));
        // Between keys: t = (1.25 − 1)/1 = 0.25 → 0.25·v1; t = (3 − 2)/2 = 0.5 → midpoint.
        assert_eq!(sample_track(&linear, 1.25), DVec3::new(0.5, 1.0, -0.5));
        assert_eq!(sample_track(&linear, 3.0), DVec3::new(2.0, 2.0, -1.0));
        assert_eq!(sample_track(&step, 3.99), DVec3::new(2.0, 4.0, -2.0));
    }

    #[test]
    fn cubic_spline_matches_the_hermite_formula() {
        // Keys at 0 and 2 (t_d = 2), stored [a, v, b] per key. At t_c = 0.5: t = 0.25,
        // h00 = 2t³−3t²+1 = 0.84375, h10 = t³−2t²+t = 0.140625, h01 = −2t³+3t² = 0.15625, h11 = t³−t² = −0.046875.
        // v = h00·v0 + t_d·h10·b0 + h01·v1 + t_d·h11·a1 with v0 = 1, b0 = 3, v1 = 5, a1 = −1 (x component):
        // 0.84375 + 2·0.140625·3 + 0.15625·5 + 2·(−0.046875)·(−1) = 2.5625.
        let track = vec_track(
            &[0.0, 2.0],
            &[[9.0, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [5.0, 0.0, 0.0], [9.0, 0.0, 0.0]],
            Interpolation::CubicSpline,
        );
        assert!((sample_track(&track, 0.5).x - 2.5625).abs() < 1e-15);
        // Keys and clamping use the value, never the tangents.
        assert_eq!(sample_track(&track, 0.0).x, 1.0);
        assert_eq!(sample_track(&track, 2.0).x, 5.0);
        assert_eq!(sample_track(&track, -1.0).x, 1.0);
        assert_eq!(sample_track(&track, 3.0).x, 5.0);
    }

    #[test]
    fn linear_rotation_is_shortest_path_slerp() {
        // 10° and 350° about Y stored with opposite signs: the short way passes through 0°, not 180°.
        let a = Quat::from_rotation_y(10f32.to_radians());
        let b = -Quat::from_rotation_y(-10f32.to_radians());
        let track = Track::new(Arc::from([0.0, 1.0].as_slice()), vec![a, b], Interpolation::Linear).unwrap();
        let mid = sample_track(&track, 0.5);
        assert!(mid.angle_between(DQuat::IDENTITY) < 1e-6, "{mid:?}");
        // A quarter of the way: 5°.
        let quarter = sample_track(&track, 0.25);
        assert!(quarter.angle_between(DQuat::from_rotation_y(5f64.to_radians())) < 1e-6);
    }

    #[test]
    fn rotation_keys_are_normalised() {
        let short = Quat::from_xyzw(0.0, 0.0, 0.707, 0.707);
        let track = Track::new(Arc::from([0.0, 1.0].as_slice()), vec![short, short], Interpolation::Step).unwrap();
        let q = sample_track(&track, 0.0);
        assert!((q.length() - 1.0).abs() < 1e-15);
        assert!(q.angle_between(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2)) < 1e-6);
    }

    #[test]
    fn cubic_rotation_is_normalised() {
        let q0 = Quat::from_rotation_x(0.0);
        let q1 = Quat::from_rotation_x(1.0);
        let zero = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        let track = Track::new(
            Arc::from([0.0, 1.0].as_slice()),
            vec![zero, q0, zero, zero, q1, zero],
            Interpolation::CubicSpline,
        )
        .unwrap();
        // h00 = h01 = 0.5 at t = 0.5: the normalised sum of q0 and q1 is the half-way rotation.
        let mid = sample_track(&track, 0.5);
        assert!((mid.length() - 1.0).abs() < 1e-15);
        assert!(mid.angle_between(DQuat::from_rotation_x(0.5)) < 1e-6);
    }
}
