//! Affine matrices as a whole: the inverse of one that may be singular, and the size of its linear part.

use glam::{DMat3, DMat4};

use crate::model::affine;

/// A matrix counts as singular below this `|det|` relative to its size ([`frobenius`]) cubed.
const SINGULAR: f64 = 1e-12;

/// The inverse of an affine matrix, or `None` when it is singular (or not finite).
pub fn affine_inverse(m: &DMat4) -> Option<DMat4> {
    let linear = DMat3::from_mat4(*m);
    let size = frobenius(m);
    let determinant = linear.determinant();
    let regular = determinant.abs() > SINGULAR * size * size * size && determinant.is_finite();
    if !regular {
        return None;
    }
    let inverse = linear.inverse();
    Some(affine(inverse, -(inverse * m.w_axis.truncate())))
}

/// The Frobenius norm of the 3×3 part: at least the largest factor by which the matrix scales a length.
pub fn frobenius(m: &DMat4) -> f64 {
    let linear = DMat3::from_mat4(*m);
    (linear.x_axis.length_squared() + linear.y_axis.length_squared() + linear.z_axis.length_squared()).sqrt()
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;

    #[test]
    fn the_inverse_undoes_the_matrix_and_a_collapse_has_none() {
        let m = DMat4::from_scale_rotation_translation(
            DVec3::new(2.0, 0.5, 3.0),
            DQuat::from_rotation_y(0.4),
            DVec3::new(1.0, -2.0, 0.5),
        );
        let inverse = affine_inverse(&m).unwrap();
        assert!((inverse * m).abs_diff_eq(DMat4::IDENTITY, 1e-12));
        assert_eq!(affine_inverse(&DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0))), None);
        assert_eq!(affine_inverse(&DMat4::from_scale(DVec3::splat(f64::NAN))), None);
        assert!((frobenius(&DMat4::from_scale(DVec3::new(3.0, 4.0, 0.0))) - 5.0).abs() < 1e-15);
    }
}
