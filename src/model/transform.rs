//! A bone's local transform: translation, rotation, scale, and the rare stretch rotation of a sheared rest matrix.

use super::Unit;
use glam::{DMat3, DMat4, DQuat, DVec3};

/// How far from an axis, relative to its length, a converted axis may point: exporters write quarter turns in
/// single precision (Blender's cos 90° is 4.4e-8).
pub const CONVERTS: f64 = 1e-6;

/// `L = T(translation)·R(rotation)·U·S(scale)·Uᵀ` with `U = R(stretch)`.
///
/// `stretch` is the identity for everything a TRS format can say; it is only set when a rest matrix with shear
/// (a glTF `matrix` node, say) is kept exactly. A mirrored matrix carries its sign in `scale` (`F = −I` commutes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub translation: DVec3,
    pub rotation: DQuat,
    pub scale: DVec3,
    pub stretch: DQuat,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform =
        Transform { translation: DVec3::ZERO, rotation: DQuat::IDENTITY, scale: DVec3::ONE, stretch: DQuat::IDENTITY };

    pub fn from_trs(translation: DVec3, rotation: DQuat, scale: DVec3) -> Self {
        Transform { translation, rotation, scale, stretch: DQuat::IDENTITY }
    }

    /// Whether the scale part is diagonal in the bone's frame (no stretch rotation).
    pub fn is_trs(&self) -> bool {
        self.stretch == DQuat::IDENTITY
    }

    /// The symmetric scale part `U·S·Uᵀ`.
    pub fn scale_matrix(&self) -> DMat3 {
        if self.is_trs() {
            DMat3::from_diagonal(self.scale)
        } else {
            let u = DMat3::from_quat(self.stretch);
            u * DMat3::from_diagonal(self.scale) * u.transpose()
        }
    }

    /// `T·R`: the transform without its own scale.
    pub fn rigid_matrix(&self) -> DMat4 {
        DMat4::from_rotation_translation(self.rotation, self.translation)
    }

    /// Whether the transform only changes axis conventions and units: no translation, and a linear part that maps
    /// each axis onto ± another, all scaled alike by a ratio of units ([`Unit::is_ratio`]: quarter turns, mirrors,
    /// 0.01 or 100, not an authored 0.03), to within `CONVERTS` of its length.
    pub fn only_converts(&self) -> bool {
        let linear = DMat3::from_quat(self.rotation) * self.scale_matrix();
        let scale = linear.x_axis.length();
        let tolerance = CONVERTS * scale;
        let mut taken = [false; 3];
        let onto_axes = [linear.x_axis, linear.y_axis, linear.z_axis].into_iter().all(|column| {
            let axis = column.abs().max_position();
            let fresh = !std::mem::replace(&mut taken[axis], true);
            let off_axis = (column - DVec3::AXES[axis] * column[axis]).length();
            fresh && (column[axis].abs() - scale).abs() <= tolerance && off_axis <= tolerance
        });
        Unit::is_ratio(scale) && self.translation.length() <= tolerance && onto_axes
    }

    /// The full local matrix `T·R·U·S·Uᵀ`.
    pub fn matrix(&self) -> DMat4 {
        if self.is_trs() {
            DMat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
        } else {
            let m = DMat3::from_quat(self.rotation) * self.scale_matrix();
            affine(m, self.translation)
        }
    }
}

/// The affine matrix with linear part `m` and translation `t`.
pub fn affine(m: DMat3, t: DVec3) -> DMat4 {
    DMat4::from_cols(m.x_axis.extend(0.0), m.y_axis.extend(0.0), m.z_axis.extend(0.0), t.extend(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretched_matrix_matches_trs_when_stretch_is_identity() {
        let t = Transform::from_trs(DVec3::new(1.0, 2.0, 3.0), DQuat::from_rotation_y(0.7), DVec3::new(2.0, 0.5, -1.0));
        let mut stretched = t;
        stretched.stretch = DQuat::from_rotation_z(1e-300); // not bit-identical to IDENTITY: takes the other path
        assert!(t.matrix().abs_diff_eq(stretched.matrix(), 1e-12));
    }

    #[test]
    fn conversions_turn_axes_onto_axes_and_scale_alike() {
        let quarter = std::f64::consts::FRAC_PI_2;
        let trs = |t: DVec3, r: DQuat, s: DVec3| Transform::from_trs(t, r, s);
        // Blender's FBX armature: −90° about X, in single precision; a unit scale; a mirror; nothing at all.
        let blender = trs(DVec3::ZERO, DQuat::from_rotation_x(f64::from(-quarter as f32)), DVec3::ONE);
        assert!(blender.only_converts());
        assert!(trs(DVec3::ZERO, DQuat::from_rotation_y(quarter), DVec3::splat(0.01)).only_converts());
        assert!(trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(1.0, 1.0, -1.0)).only_converts());
        assert!(Transform::IDENTITY.only_converts());
        // Not conversions: a move, a turn between axes, a non-uniform scale, a collapse, a stretch off the axes.
        assert!(!trs(DVec3::X * 1e-3, DQuat::IDENTITY, DVec3::ONE).only_converts());
        assert!(!trs(DVec3::ZERO, DQuat::from_rotation_z(0.3), DVec3::ONE).only_converts());
        assert!(!trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(1.0, 2.0, 1.0)).only_converts());
        assert!(!trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::ZERO).only_converts());
        let stretch = DQuat::from_rotation_z(0.5);
        let sheared = Transform { stretch, ..trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(2.0, 1.0, 1.0)) };
        assert!(!sheared.only_converts());
    }

    #[test]
    fn stretch_is_applied_as_u_s_ut() {
        // U = 90° about Z swaps the roles of x and y: U·diag(2,1,1)·Uᵀ = diag(1,2,1).
        let t = Transform {
            stretch: DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
            scale: DVec3::new(2.0, 1.0, 1.0),
            ..Transform::IDENTITY
        };
        assert!(t.scale_matrix().abs_diff_eq(DMat3::from_diagonal(DVec3::new(1.0, 2.0, 1.0)), 1e-12));
    }
}
