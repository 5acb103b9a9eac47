//! Reading a clip with another interpolation than the authored one: the nearest key (the "jaggy" playback of a
//! runtime that shows the closest key), linear, or cubic; rotations by slerp, nlerp or per-component Euler XYZ angles.
//!
//! Cubic is Catmull-Rom through the keys: between keys `k` and `k + 1` a Hermite segment whose tangent at each key
//! is the slope to its neighbours, `m_k = (p_{k+1} − p_{k−1}) / (t_{k+1} − t_{k−1})` (one-sided at the ends). With
//! evenly spaced keys that is the classic `½(p_{k+1} − p_{k−1})` per key interval. A cubic-spline track keeps its
//! authored tangents. Cubic rotations are the same spline on quaternion components (each key on the hemisphere of
//! the one before it), normalised, for slerp and nlerp alike; on the Euler angles for `euler`.
//!
//! Euler XYZ angles are glam's `EulerRot::XYZ`; each key's angles are moved by whole turns to lie within half a
//! turn of the previous key's, so the interpolation never spins the long way round one axis (it still does
//! everything else Euler interpolation is known for: paths off the great arc, uneven speed, gimbal lock).

use std::f64::consts::TAU;

use glam::{DQuat, DVec3, EulerRot, Quat, Vec3};

use super::super::sample::{Interpolate, Span, TrackSampler, hermite_basis, key_value, sample_track_near};
use crate::math::{nlerp, slerp};
use crate::model::{Choice, Interpolation, Track};

/// Which values between keys.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum KeyInterpolation {
    /// As the file says.
    #[default]
    Authored,
    /// The key closest in time (the later one at exactly half way).
    Nearest,
    Linear,
    /// Catmull-Rom through the keys (a cubic-spline track keeps its own tangents).
    Cubic,
}

impl Choice for KeyInterpolation {
    const ALL: &'static [KeyInterpolation] =
        &[KeyInterpolation::Authored, KeyInterpolation::Nearest, KeyInterpolation::Linear, KeyInterpolation::Cubic];

    fn id(self) -> &'static str {
        match self {
            KeyInterpolation::Authored => "authored",
            KeyInterpolation::Nearest => "nearest",
            KeyInterpolation::Linear => "linear",
            KeyInterpolation::Cubic => "cubic",
        }
    }

    fn description(self) -> &'static str {
        match self {
            KeyInterpolation::Authored => "as the file says",
            KeyInterpolation::Nearest => "the key closest in time (the later one at exactly half way)",
            KeyInterpolation::Linear => "straight lines between keys",
            KeyInterpolation::Cubic => "Catmull-Rom through the keys (a cubic-spline track keeps its own tangents)",
        }
    }
}

/// How rotation keys are interpolated wherever keys are mixed linearly (authored linear tracks included).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RotationInterpolation {
    /// What glTF specifies for linear rotation tracks.
    #[default]
    Slerp,
    Nlerp,
    /// Per-component Euler XYZ angles.
    Euler,
}

impl Choice for RotationInterpolation {
    const ALL: &'static [RotationInterpolation] =
        &[RotationInterpolation::Slerp, RotationInterpolation::Nlerp, RotationInterpolation::Euler];

    fn id(self) -> &'static str {
        match self {
            RotationInterpolation::Slerp => "slerp",
            RotationInterpolation::Nlerp => "nlerp",
            RotationInterpolation::Euler => "euler",
        }
    }

    fn description(self) -> &'static str {
        match self {
            RotationInterpolation::Slerp => "constant angular speed (what glTF specifies for linear rotation tracks)",
            RotationInterpolation::Nlerp => "quaternion components mixed, then normalised",
            RotationInterpolation::Euler => "per-component Euler XYZ angles",
        }
    }
}

impl RotationInterpolation {
    /// The rotation a fraction `t` of the way from `a` to `b`.
    pub fn mix(self, a: DQuat, b: DQuat, t: f64) -> DQuat {
        match self {
            RotationInterpolation::Slerp => slerp(a, b, t),
            RotationInterpolation::Nlerp => nlerp(a, b, t),
            RotationInterpolation::Euler => {
                let from = euler(a);
                from_euler(from.lerp(unwrap(euler(b), from), t))
            }
        }
    }
}

/// An interpolation override for every track of a clip. The default reads every track as authored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Resampling {
    pub keys: KeyInterpolation,
    pub rotation: RotationInterpolation,
}

impl Resampling {
    pub fn is_authored(&self) -> bool {
        *self == Resampling::default()
    }

    /// One track's value at `time`.
    pub fn sample<T: Channel>(&self, track: &Track<T>, time: f64) -> T::Wide {
        self.sample_near(track, time, &mut 0)
    }

    /// [`Resampling::sample`], the key search starting at `*hint` (see `Span::locate_near`).
    fn sample_near<T: Channel>(&self, track: &Track<T>, time: f64, hint: &mut usize) -> T::Wide {
        let segment = Segment::of(self.keys, track.interpolation());
        if segment == Segment::Hermite {
            return sample_track_near(track, time, hint);
        }
        let (k, t) = match Span::locate_near(track.times(), time, hint) {
            Span::Key(k) => return key_value(track, k),
            Span::Between { k, t } => (k, t),
        };
        match segment {
            Segment::Step => key_value(track, k),
            Segment::Nearest => key_value(track, if t < 0.5 { k } else { k + 1 }),
            Segment::Linear => T::mix(key_value(track, k), key_value(track, k + 1), t, self.rotation),
            Segment::CatmullRom | Segment::Hermite => {
                let (keys, weights) = catmull_rom(track.times(), k, t);
                T::combine(keys.map(|i| key_value(track, i)), weights, self.rotation)
            }
        }
    }
}

impl TrackSampler for Resampling {
    fn vector(&self, track: &Track<Vec3>, time: f64, hint: &mut usize) -> DVec3 {
        self.sample_near(track, time, hint)
    }

    fn rotation(&self, track: &Track<Quat>, time: f64, hint: &mut usize) -> DQuat {
        self.sample_near(track, time, hint)
    }
}

/// How one segment between two keys is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Segment {
    Step,
    Nearest,
    Linear,
    CatmullRom,
    /// The authored cubic spline.
    Hermite,
}

impl Segment {
    fn of(keys: KeyInterpolation, authored: Interpolation) -> Segment {
        match (keys, authored) {
            (KeyInterpolation::Authored, Interpolation::Step) => Segment::Step,
            (KeyInterpolation::Authored, Interpolation::Linear) | (KeyInterpolation::Linear, _) => Segment::Linear,
            (KeyInterpolation::Authored | KeyInterpolation::Cubic, Interpolation::CubicSpline) => Segment::Hermite,
            (KeyInterpolation::Nearest, _) => Segment::Nearest,
            (KeyInterpolation::Cubic, _) => Segment::CatmullRom,
        }
    }
}

/// The four keys around segment `k` (repeated at the ends) and the weight of each in the Catmull-Rom value at
/// fraction `t`. The Hermite form `h00·p1 + h10·d·m1 + h01·p2 + h11·d·m2` with `d = t2 − t1`,
/// `m1 = (p2 − p0)/(t2 − t0)` and `m2 = (p3 − p1)/(t3 − t1)` is linear in the keys.
fn catmull_rom(times: &[f64], k: usize, t: f64) -> ([usize; 4], [f64; 4]) {
    let last = times.len() - 1;
    let keys = [k.saturating_sub(1), k, k + 1, (k + 2).min(last)];
    let [t0, t1, t2, t3] = keys.map(|i| times[i]);
    let [h00, h10, h01, h11] = hermite_basis(t);
    let d = t2 - t1;
    let (a, b) = (h10 * d / (t2 - t0), h11 * d / (t3 - t1));
    (keys, [-a, h00 - b, h01 + a, b])
}

/// A key value type that can be resampled.
pub trait Channel: Interpolate {
    fn mix(a: Self::Wide, b: Self::Wide, t: f64, rotation: RotationInterpolation) -> Self::Wide;
    /// `Σ weights[i] · keys[i]` over four consecutive keys.
    fn combine(keys: [Self::Wide; 4], weights: [f64; 4], rotation: RotationInterpolation) -> Self::Wide;
}

impl Channel for Vec3 {
    fn mix(a: DVec3, b: DVec3, t: f64, _: RotationInterpolation) -> DVec3 {
        a.lerp(b, t)
    }

    fn combine(keys: [DVec3; 4], weights: [f64; 4], _: RotationInterpolation) -> DVec3 {
        keys.iter().zip(weights).map(|(p, w)| *p * w).sum()
    }
}

impl Channel for Quat {
    fn mix(a: DQuat, b: DQuat, t: f64, rotation: RotationInterpolation) -> DQuat {
        rotation.mix(a, b, t)
    }

    fn combine(keys: [DQuat; 4], weights: [f64; 4], rotation: RotationInterpolation) -> DQuat {
        if rotation == RotationInterpolation::Euler {
            let mut angles = keys.map(euler);
            for i in [0, 2, 3] {
                angles[i] = unwrap(angles[i], angles[if i == 0 { 1 } else { i - 1 }]);
            }
            return from_euler(angles.iter().zip(weights).map(|(a, w)| *a * w).sum());
        }
        let mut aligned = keys;
        for i in [0, 2, 3] {
            let previous = aligned[if i == 0 { 1 } else { i - 1 }];
            if aligned[i].dot(previous) < 0.0 {
                aligned[i] = -aligned[i];
            }
        }
        let q: DQuat =
            aligned.iter().zip(weights).map(|(q, w)| *q * w).fold(DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), |s, q| s + q);
        if q.length_squared() > 0.0 { q.normalize() } else { keys[1] }
    }
}

fn euler(q: DQuat) -> DVec3 {
    DVec3::from(q.to_euler(EulerRot::XYZ))
}

fn from_euler(angles: DVec3) -> DQuat {
    DQuat::from_euler(EulerRot::XYZ, angles.x, angles.y, angles.z)
}

/// `angles` moved by whole turns, per component, to within half a turn of `near`.
fn unwrap(angles: DVec3, near: DVec3) -> DVec3 {
    let d = angles - near;
    near + d - TAU * (d / TAU).round()
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::eval::sample_track;

    fn x_track(times: &[f64], xs: &[f32], interpolation: Interpolation) -> Track<Vec3> {
        Track::new(Arc::from(times), xs.iter().map(|&x| Vec3::new(x, 0.0, 0.0)).collect::<Arc<[_]>>(), interpolation)
            .unwrap()
    }

    fn keys(keys: KeyInterpolation) -> Resampling {
        Resampling { keys, ..Resampling::default() }
    }

    #[test]
    fn nearest_linear_and_authored_step() {
        let track = x_track(&[0.0, 1.0, 3.0], &[0.0, 10.0, 30.0], Interpolation::Step);
        let x = |r: Resampling, t: f64| r.sample(&track, t).x;
        assert_eq!(x(keys(KeyInterpolation::Authored), 0.9), 0.0);
        assert_eq!(x(keys(KeyInterpolation::Nearest), 0.4), 0.0);
        assert_eq!(x(keys(KeyInterpolation::Nearest), 0.5), 10.0, "half way goes to the later key");
        assert_eq!(x(keys(KeyInterpolation::Nearest), 1.9), 10.0);
        assert_eq!(x(keys(KeyInterpolation::Nearest), 2.1), 30.0);
        // Linear: (2 − 1)/(3 − 1) = 0.5 of the way from 10 to 30.
        assert_eq!(x(keys(KeyInterpolation::Linear), 2.0), 20.0);
        // Outside the keys: clamped, whatever the mode.
        assert_eq!(x(keys(KeyInterpolation::Cubic), 5.0), 30.0);
        assert_eq!(x(keys(KeyInterpolation::Nearest), -1.0), 0.0);
    }

    #[test]
    fn cubic_is_catmull_rom_through_the_keys() {
        // Even keys p = 0, 1, 3, 4 at t = 0..3. Classic Catmull-Rom at u = 0.5 of the middle segment:
        // ½(2·p1 + (p2 − p0)·u + (2p0 − 5p1 + 4p2 − p3)·u² + (−p0 + 3p1 − 3p2 + p3)·u³)
        // = ½(2 + 3·0.5 + 3·0.25 − 2·0.125) = 2.
        let track = x_track(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 3.0, 4.0], Interpolation::Linear);
        let cubic = keys(KeyInterpolation::Cubic);
        assert!((cubic.sample(&track, 1.5).x - 2.0).abs() < 1e-15);
        // At u = 0.25: ½(2 + 0.75 + 0.1875 − 0.03125) = 1.453125.
        assert!((cubic.sample(&track, 1.25).x - 1.453125).abs() < 1e-15);
        // First segment, one-sided tangent at key 0: m0 = 1, m1 = (3 − 0)/2 = 1.5. At u = 0.5:
        // h00·0 + h10·1 + h01·1 + h11·1.5 = 0.125 + 0.5 − 0.1875 = 0.4375.
        assert!((cubic.sample(&track, 0.5).x - 0.4375).abs() < 1e-15);
        // Keys are passed through.
        assert_eq!(cubic.sample(&track, 2.0).x, 3.0);
    }

    #[test]
    fn uneven_keys_use_the_slope_across_neighbours() {
        // Keys 0, 1, 2 at t = 0, 1, 3 with values 0, 1, 5. Segment 1→3 (d = 2), u = 0.5:
        // m1 = (5 − 0)/(3 − 0) = 5/3, m2 (one-sided) = (5 − 1)/2 = 2;
        // h00·1 + h10·2·m1 + h01·5 + h11·2·m2 = 0.5 + 0.125·10/3 + 2.5 − 0.125·4 = 2.916666…
        let track = x_track(&[0.0, 1.0, 3.0], &[0.0, 1.0, 5.0], Interpolation::Linear);
        let value = keys(KeyInterpolation::Cubic).sample(&track, 2.0).x;
        assert!((value - (3.0 + 0.125 * 10.0 / 3.0 - 0.5)).abs() < 1e-14, "{value}");
    }

    fn rotation_track(rotations: &[DQuat]) -> Track<Quat> {
        let times: Vec<f64> = (0..rotations.len()).map(|i| i as f64).collect();
        Track::new(Arc::from(times), rotations.iter().map(|q| q.as_quat()).collect::<Arc<[_]>>(), Interpolation::Linear)
            .unwrap()
    }

    #[test]
    fn euler_interpolates_each_angle() {
        let b = from_euler(DVec3::new(0.6, 0.4, 0.2));
        let track = rotation_track(&[DQuat::IDENTITY, b]);
        let euler = Resampling { rotation: RotationInterpolation::Euler, ..Resampling::default() };
        let mid = euler.sample(&track, 0.5);
        assert!(mid.abs_diff_eq(from_euler(DVec3::new(0.3, 0.2, 0.1)), 1e-6), "{mid:?}");
        // Not the slerp half-way rotation: Euler paths are not great arcs.
        let slerped = Resampling::default().sample(&track, 0.5);
        assert!(mid.angle_between(slerped) > 1e-3);
        // Across ±180° the angle goes the short way: 170° → −170° about X passes 180°, not 0°.
        let track = rotation_track(&[
            DQuat::from_rotation_x(170f64.to_radians()),
            DQuat::from_rotation_x(-170f64.to_radians()),
        ]);
        let mid = euler.sample(&track, 0.5);
        assert!(mid.angle_between(DQuat::from_rotation_x(std::f64::consts::PI)) < 1e-6, "{mid:?}");
    }

    #[test]
    fn nlerp_and_cubic_rotations_stay_unit_and_pass_keys() {
        let qs: Vec<DQuat> =
            (0..4).map(|i| DQuat::from_rotation_z(0.4 * i as f64) * DQuat::from_rotation_x(0.1 * i as f64)).collect();
        let track = rotation_track(&qs);
        for rotation in [RotationInterpolation::Slerp, RotationInterpolation::Nlerp, RotationInterpolation::Euler] {
            for key_mode in [KeyInterpolation::Linear, KeyInterpolation::Cubic] {
                let r = Resampling { keys: key_mode, rotation };
                for i in 0..30 {
                    let q = r.sample(&track, i as f64 * 0.1);
                    assert!((q.length() - 1.0).abs() < 1e-12);
                }
                assert!(r.sample(&track, 2.0).abs_diff_eq(key_value(&track, 2), 1e-7));
            }
        }
        // About one axis, Catmull-Rom on components of evenly turning keys stays on the axis, and nlerp at the
        // midpoint of two keys is the half angle (symmetry).
        let nlerp = Resampling { rotation: RotationInterpolation::Nlerp, ..Resampling::default() };
        let z_track = rotation_track(&[DQuat::IDENTITY, DQuat::from_rotation_z(1.0)]);
        assert!(nlerp.sample(&z_track, 0.5).abs_diff_eq(DQuat::from_rotation_z(0.5), 1e-7));
    }

    #[test]
    fn the_default_reads_tracks_as_authored() {
        let track = x_track(&[0.0, 1.0, 3.0], &[0.0, 10.0, 30.0], Interpolation::Linear);
        for t in [-1.0, 0.0, 0.3, 1.0, 2.2, 3.0, 4.0, f64::NAN] {
            assert_eq!(Resampling::default().sample(&track, t), sample_track(&track, t));
        }
        assert!(Resampling::default().is_authored());
    }
}
