//! Quaternion interpolation exactly as glTF's Appendix C writes it.

use glam::DQuat;

/// Spherical linear interpolation along the shortest path; falls back to linear interpolation (then normalised)
/// when the two rotations are too close for `sin(a)` to be divided by.
pub fn slerp(a: DQuat, b: DQuat, t: f64) -> DQuat {
    let dot = a.dot(b);
    let sign = if dot < 0.0 { -1.0 } else { 1.0 };
    let cos = dot.abs().min(1.0);
    let angle = cos.acos();
    // sin(acos(c)) without a third sine.
    let sin = (1.0 - cos * cos).sqrt();
    if sin < 1e-9 {
        return (a * (1.0 - t) + b * (sign * t)).normalize();
    }
    a * ((angle * (1.0 - t)).sin() / sin) + b * (sign * (angle * t).sin() / sin)
}

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
    fn nlerp_is_normalised_and_shortest() {
        let a = DQuat::from_rotation_x(0.0);
        let b = DQuat::from_rotation_x(1.0);
        let q = nlerp(a, -b, 0.5);
        assert!((q.length() - 1.0).abs() < 1e-15);
        // Halfway by nlerp between two rotations about one axis is the half angle (symmetry).
        assert!(q.abs_diff_eq(DQuat::from_rotation_x(0.5), 1e-14));
    }
}
