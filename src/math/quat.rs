//! Quaternion interpolation exactly as glTF's Appendix C writes it.

use glam::DQuat;

/// Spherical linear interpolation along the shortest path; falls back to linear interpolation (then normalised)
/// when the two rotations are too close for `sin(a)` to be divided by.
pub fn slerp(a: DQuat, b: DQuat, t: f64) -> DQuat {
    Slerp::new(a, b).at(t)
}

/// Slerp between two rotations prepared for many fractions: the angle between them is found once (sampling a key
/// interval at several times costs one sine–cosine pair per time, no inverse cosine).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slerp {
    a: DQuat,
    /// `b`, or `−b` when that is nearer `a` (the shortest path).
    b: DQuat,
    /// `cos θ`, `sin θ`, `1/sin θ` and `θ` of the angle between `a` and `b` as 4-vectors.
    cos: f64,
    sin: f64,
    inverse_sin: f64,
    angle: f64,
}

impl Slerp {
    pub fn new(a: DQuat, b: DQuat) -> Self {
        let dot = a.dot(b);
        let b = if dot < 0.0 { -b } else { b };
        let cos = dot.abs().min(1.0);
        // sin(acos(c)) without a sine.
        let sin = (1.0 - cos * cos).sqrt();
        let (inverse_sin, angle) = if sin < NEARLY_EQUAL { (0.0, 0.0) } else { (1.0 / sin, cos.acos()) };
        Slerp { a, b, cos, sin, inverse_sin, angle }
    }

    /// The rotation a fraction `t` of the way.
    #[inline]
    pub fn at(&self, t: f64) -> DQuat {
        let Slerp { a, b, cos, sin, inverse_sin, angle } = *self;
        if sin < NEARLY_EQUAL {
            return (a * (1.0 - t) + b * t).normalize();
        }
        // sin((1 − t)·θ) = sin θ·cos tθ − cos θ·sin tθ: one sine-cosine pair instead of two sines.
        let (sin_t, cos_t) = (angle * t).sin_cos();
        a * ((sin * cos_t - cos * sin_t) * inverse_sin) + b * (sin_t * inverse_sin)
    }
}

/// Below this `sin θ` the rotations are the same to rounding, and slerp falls back to normalised lerp.
const NEARLY_EQUAL: f64 = 1e-9;

/// Normalised linear interpolation along the shortest path.
pub fn nlerp(a: DQuat, b: DQuat, t: f64) -> DQuat {
    let sign = if a.dot(b) < 0.0 { -1.0 } else { 1.0 };
    (a * (1.0 - t) + b * (sign * t)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slerp_halfway_between_axis_rotations() {
        // Rotations about one axis: slerp interpolates the angle linearly.
        let a = DQuat::from_rotation_z(0.2);
        let b = DQuat::from_rotation_z(1.4);
        assert!(slerp(a, b, 0.25).abs_diff_eq(DQuat::from_rotation_z(0.5), 1e-14));
        // The same rotation written with the opposite sign is reached the short way.
        assert!(slerp(a, -b, 0.25).abs_diff_eq(DQuat::from_rotation_z(0.5), 1e-14));
        assert!(slerp(a, a, 0.7).abs_diff_eq(a, 1e-15));
    }

    #[test]
    fn slerp_keeps_unit_length_and_constant_angular_speed() {
        let a = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        let b = DQuat::from_euler(glam::EulerRot::XYZ, -0.7, 0.4, 0.1);
        // The angle between two rotations by atan2, accurate near 0 too (acos of a dot product is not).
        let angle = |p: DQuat, q: DQuat| {
            let d = p.inverse() * q;
            2.0 * d.xyz().length().atan2(d.w.abs())
        };
        let total = angle(a, b);
        for i in 0..=20 {
            let t = f64::from(i) / 20.0;
            let q = slerp(a, b, t);
            assert!((q.length() - 1.0).abs() < 1e-15, "{t}: length {}", q.length());
            assert!((angle(a, q) - t * total).abs() < 1e-14, "{t}: {} of {total}", angle(a, q));
        }
    }

    #[test]
    fn nlerp_is_normalised_and_shortest() {
        let a = DQuat::from_rotation_x(0.0);
        let b = DQuat::from_rotation_x(1.0);
        let q = nlerp(a, -b, 0.5);
        assert!((q.length() - 1.0).abs() < 1e-15);
        // Halfway by nlerp between two rotations about one axis is the half angle (symmetry).
        assert!(q.abs_diff_eq(DQuat::from_rotation_x(0.5), 1e-14));
    }
}
