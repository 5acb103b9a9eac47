//! Does a skin's bind pose agree with the skeleton's rest pose? Keys are stored relative to one of them;
//! when the two disagree, engines that start from the rest pose and engines that start from the bind pose show
//! different things. The check names the joints and says by how much.
//!
//! Bind matrices live in the skin's bind space, which may differ from the model space by the mesh node's transform
//! and any unit or axis conversion ([`crate::eval::skin_bind_spaces`]); so a joint is bound elsewhere when its bind
//! matrix, carried into model space by its skin's common bind space `S`, is not its rest model matrix.

use glam::DMat4;
use serde::Serialize;

use crate::eval::{Hierarchy, ModelPose, invert, skin_bind_spaces};
use crate::math::decompose;
use crate::model::Rig;

/// How far a bind matrix may be from the rest matrix before it is reported.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BindTolerance {
    /// Model units (default 1e-4).
    pub distance: f64,
    /// Degrees (default 0.01).
    pub angle_deg: f64,
    /// Relative change of any scale factor (default 1e-4).
    pub scale: f64,
}

impl Default for BindTolerance {
    fn default() -> Self {
        BindTolerance { distance: 1e-4, angle_deg: 0.01, scale: 1e-4 }
    }
}

/// One joint whose bind matrix `S · IBM⁻¹` (in model space) is not its rest model matrix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BindMismatch {
    pub bone: usize,
    pub name: String,
    /// Between the two origins, in model units.
    pub distance: f64,
    /// Between the two rotations (polar decomposition), in degrees.
    pub angle_deg: f64,
    /// The largest relative change of a scale factor (1 for a factor that is zero at rest and not in the bind).
    pub scale_change: f64,
}

/// Every skin joint whose bind matrix in model space differs from its rest model matrix (evaluated by `hierarchy`)
/// by more than `tolerance`, in bone order (a joint of several skins once, with its first skin's bind; a joint whose
/// inverse bind matrix cannot be inverted has no bind to compare).
pub fn bind_mismatches(rig: &Rig, hierarchy: &Hierarchy, tolerance: &BindTolerance) -> Vec<BindMismatch> {
    let mut rest = ModelPose::default();
    hierarchy.evaluate(&rig.skeleton.rest_pose(), &mut rest);
    let spaces = skin_bind_spaces(rig, &rest.model);
    let mut bound: Vec<Option<DMat4>> = vec![None; rig.skeleton.len()];
    for (skin, space) in rig.skins.iter().zip(&spaces) {
        for (&joint, ibm) in skin.joints.iter().zip(&skin.inverse_bind) {
            if let Some(slot @ None) = bound.get_mut(joint) {
                *slot = invert(ibm).map(|bind| *space * bind);
            }
        }
    }
    bound
        .into_iter()
        .enumerate()
        .filter_map(|(bone, bind)| {
            let mismatch = compare(bone, rig.skeleton.bone(bone).name.clone(), &bind?, &rest.model[bone]);
            let off = !(mismatch.distance <= tolerance.distance
                && mismatch.angle_deg <= tolerance.angle_deg
                && mismatch.scale_change <= tolerance.scale);
            off.then_some(mismatch)
        })
        .collect()
}

fn compare(bone: usize, name: String, bind: &DMat4, rest: &DMat4) -> BindMismatch {
    let (b, r) = (decompose(bind), decompose(rest));
    BindMismatch {
        bone,
        name,
        distance: b.translation.distance(r.translation),
        angle_deg: b.rotation.angle_between(r.rotation).to_degrees(),
        scale_change: (0..3).map(|axis| scale_change(b.scale[axis], r.scale[axis])).fold(0.0, f64::max),
    }
}

/// How much a scale factor changes from `rest` to `bind`, relative to `rest`; a zero (degenerate) rest factor has no
/// such ratio, and counts as all of the bind's (1), or none when both are zero, never NaN or infinity.
fn scale_change(bind: f64, rest: f64) -> f64 {
    match (bind - rest).abs() / rest.abs() {
        change if change.is_finite() => change,
        _ if bind == rest => 0.0,
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::import::demo_rig;

    #[test]
    fn names_the_joints_bound_elsewhere_and_says_by_how_much() {
        let mut rig = demo_rig();
        let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes());
        assert!(bind_mismatches(&rig, &hierarchy, &BindTolerance::default()).is_empty(), "bound at rest");
        // The forearm (joint 1, bone 2) rests at (1, 1.5, 0); bind it 3 cm higher, turned 10° about Z.
        let bound =
            DMat4::from_rotation_translation(DQuat::from_rotation_z(10f64.to_radians()), DVec3::new(1.0, 1.53, 0.0));
        rig.skins[0].inverse_bind[1] = bound.inverse();
        let found = bind_mismatches(&rig, &hierarchy, &BindTolerance::default());
        assert_eq!(found.len(), 1);
        assert_eq!((found[0].bone, found[0].name.as_str()), (2, "forearm"));
        assert!((found[0].distance - 0.03).abs() < 1e-12);
        assert!((found[0].angle_deg - 10.0).abs() < 1e-9);
        assert!(found[0].scale_change < 1e-12);
    }

    #[test]
    fn scale_changes_are_relative_to_the_rest_and_finite_at_zero() {
        assert_eq!(scale_change(1.5, 1.0), 0.5);
        assert_eq!(scale_change(-2.0, -4.0), 0.5, "mirrored factors compare by size");
        assert_eq!(scale_change(2.0, 0.0), 1.0, "a zero rest factor: all of the bind's");
        assert_eq!(scale_change(0.0, 0.0), 0.0);
        assert_eq!(scale_change(1.0, 1e-320), 1.0, "a ratio past f64 counts as all of it");
    }
}
