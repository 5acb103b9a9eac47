//! Every scale-inheritance mode on hand-derived cases, plus the invariants that tell them apart.

use bonescope::eval::{Hierarchy, ModelPose};
use bonescope::math::shear_deg;
use bonescope::model::{Bone, Choice, InheritMode, NodeRole, Skeleton, Transform};
use glam::{DMat3, DMat4, DQuat, DVec3};
use proptest::prelude::*;

const EPS: f64 = 1e-12;

fn chain(locals: &[Transform]) -> Skeleton {
    let bones = locals
        .iter()
        .enumerate()
        .map(|(i, rest)| Bone {
            name: format!("b{i}"),
            node: i,
            parent: i.checked_sub(1),
            rest: *rest,
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        })
        .collect();
    Skeleton::new(bones).unwrap()
}

fn evaluate(locals: &[Transform], modes: &[InheritMode]) -> Vec<DMat4> {
    let skeleton = chain(locals);
    let mut pose = ModelPose::default();
    Hierarchy::new(&skeleton, modes).unwrap().evaluate(locals, &mut pose);
    pose.model
}

fn linear(m: &DMat4) -> DMat3 {
    DMat3::from_mat4(*m)
}

/// A parent scaled (2, 1, 1) and a child 1 along X, turned 45° about Z.
fn parent_and_rotated_child() -> [Transform; 2] {
    [
        Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(2.0, 1.0, 1.0)),
        Transform::from_trs(DVec3::X, DQuat::from_rotation_z(45f64.to_radians()), DVec3::ONE),
    ]
}

fn child_under(mode: InheritMode) -> DMat4 {
    evaluate(&parent_and_rotated_child(), &[InheritMode::Full, mode])[1]
}

const C: f64 = std::f64::consts::FRAC_1_SQRT_2;

#[test]
fn full_scales_the_offset_and_shears_the_rotated_child() {
    // W = diag(2,1,1)·T(1,0,0)·Rz(45°): translation (2,0,0); columns diag(2,1,1)·(c, c, 0) and ·(−c, c, 0).
    // Their dot product is −4c² + c² = −1.5 over lengths² 2.5: 126.87°, a shear of 36.87°.
    let w = child_under(InheritMode::Full);
    assert!(w.w_axis.truncate().abs_diff_eq(DVec3::new(2.0, 0.0, 0.0), EPS));
    let expected = DMat3::from_cols(DVec3::new(2.0 * C, C, 0.0), DVec3::new(-2.0 * C, C, 0.0), DVec3::Z);
    assert!(linear(&w).abs_diff_eq(expected, EPS));
    assert!((shear_deg(&linear(&w)) - ((-0.6f64).acos().to_degrees() - 90.0)).abs() < 1e-9);
}

#[test]
fn unscaled_parent_drops_the_parent_scale_entirely() {
    // W = G_p·L with G_p = I: the offset is not scaled and the child is a pure rotation.
    let w = child_under(InheritMode::UnscaledParent);
    assert!(w.abs_diff_eq(DMat4::from_rotation_translation(DQuat::from_rotation_z(45f64.to_radians()), DVec3::X), EPS));
}

#[test]
fn segment_compensate_scales_the_offset_only() {
    // W = U_p·T(s_p ⊙ t)·R·S = T(2,0,0)·Rz(45°).
    let w = child_under(InheritMode::SegmentCompensate);
    let expected =
        DMat4::from_rotation_translation(DQuat::from_rotation_z(45f64.to_radians()), DVec3::new(2.0, 0.0, 0.0));
    assert!(w.abs_diff_eq(expected, EPS));
}

#[test]
fn componentwise_applies_parent_scale_along_the_child_axes() {
    // W = U_p·T(s_p ⊙ t)·R·S(s_p ⊙ s) = T(2,0,0)·Rz(45°)·diag(2,1,1): columns (2c, 2c, 0) and (−c, c, 0).
    let w = child_under(InheritMode::Componentwise);
    let expected = DMat3::from_cols(DVec3::new(2.0 * C, 2.0 * C, 0.0), DVec3::new(-C, C, 0.0), DVec3::Z);
    assert!(linear(&w).abs_diff_eq(expected, EPS));
    assert!(w.w_axis.truncate().abs_diff_eq(DVec3::new(2.0, 0.0, 0.0), EPS));
    assert!(shear_deg(&linear(&w)) < 1e-9);
}

#[test]
fn roots_are_their_local_matrix_in_every_mode() {
    let local = Transform::from_trs(DVec3::new(1.0, 2.0, 3.0), DQuat::from_rotation_x(0.3), DVec3::new(2.0, 0.5, 1.0));
    for &mode in InheritMode::ALL {
        assert!(evaluate(&[local], &[mode])[0].abs_diff_eq(local.matrix(), EPS), "{mode}");
    }
}

#[test]
fn compensating_child_of_a_componentwise_bone_keeps_the_grandparent_scale() {
    // ufbx: a compensating bone multiplies its scale by the inherit_scale of the parent of the nearest
    // componentwise ancestor. A (full, scale (2,1,1)) → B (componentwise, scale (1,3,1), offset (1,1,0))
    // → C (compensating, offset (1,1,0)). By hand: B's inherit scale is (1,3,1)⊙(2,1,1) = (2,3,1), so
    // C's offset is scaled by it: (2,3,0); C's scale is (1,1,1)⊙(2,1,1): the grandparent's scale survives and
    // B's own (×3 along Y) does not. B sits at (1,1,0)⊙(2,1,1) = (2,1,0).
    let locals = [
        Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(2.0, 1.0, 1.0)),
        Transform::from_trs(DVec3::new(1.0, 1.0, 0.0), DQuat::IDENTITY, DVec3::new(1.0, 3.0, 1.0)),
        Transform::from_trs(DVec3::new(1.0, 1.0, 0.0), DQuat::IDENTITY, DVec3::ONE),
    ];
    let w = evaluate(&locals, &[InheritMode::Full, InheritMode::Componentwise, InheritMode::SegmentCompensate]);
    assert!(w[1].abs_diff_eq(
        DMat4::from_scale_rotation_translation(DVec3::new(2.0, 3.0, 1.0), DQuat::IDENTITY, DVec3::new(2.0, 1.0, 0.0)),
        EPS
    ));
    let expected =
        DMat4::from_scale_rotation_translation(DVec3::new(2.0, 1.0, 1.0), DQuat::IDENTITY, DVec3::new(4.0, 4.0, 0.0));
    assert!(w[2].abs_diff_eq(expected, EPS), "{}", w[2]);
}

fn random_local() -> impl Strategy<Value = Transform> {
    let component = -1.0..1.0f64;
    let scale = 0.2..3.0f64;
    (
        (component.clone(), component.clone(), component.clone()),
        (component.clone(), component.clone(), component.clone(), component),
        (scale.clone(), scale.clone(), scale),
    )
        .prop_filter("rotation", |(_, (x, y, z, w), _)| x * x + y * y + z * z + w * w > 1e-2)
        .prop_map(|((tx, ty, tz), (x, y, z, w), (sx, sy, sz))| {
            Transform::from_trs(
                DVec3::new(tx, ty, tz),
                DQuat::from_xyzw(x, y, z, w).normalize(),
                DVec3::new(sx, sy, sz),
            )
        })
}

fn worst_shear(models: &[DMat4]) -> f64 {
    models.iter().map(|m| shear_deg(&linear(m))).fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn shear_free_modes_never_shear(locals in prop::collection::vec(random_local(), 2..6)) {
        for mode in [InheritMode::SegmentCompensate, InheritMode::Componentwise, InheritMode::UnscaledParent] {
            // The root is plain; every other bone uses the mode.
            let mut modes = vec![mode; locals.len()];
            modes[0] = InheritMode::Full;
            prop_assert!(worst_shear(&evaluate(&locals, &modes)) < 1e-7, "{mode}");
        }
    }

    #[test]
    fn full_equals_the_plain_matrix_product(locals in prop::collection::vec(random_local(), 1..6)) {
        let models = evaluate(&locals, &vec![InheritMode::Full; locals.len()]);
        let mut expected = DMat4::IDENTITY;
        for (local, model) in locals.iter().zip(&models) {
            expected *= local.matrix();
            prop_assert!(model.abs_diff_eq(expected, 1e-9));
        }
    }
}

#[test]
fn full_inheritance_does_shear() {
    assert!(worst_shear(&evaluate(&parent_and_rotated_child(), &[InheritMode::Full; 2])) > 30.0);
}

/// A parent scaled (2, 1, 0.5) and turned, a child whose rest is turned 50° about Z and which animates a further
/// rotation about X: under full inheritance the child shears.
fn blender_case(child_animated: bool) -> [Transform; 2] {
    let rest = DQuat::from_rotation_z(50f64.to_radians());
    let rotation = if child_animated { rest * DQuat::from_rotation_x(0.7) } else { rest };
    [
        Transform::from_trs(DVec3::ZERO, DQuat::from_rotation_y(0.3), DVec3::new(2.0, 1.0, 0.5)),
        Transform::from_trs(DVec3::new(0.0, 1.0, 0.0), rotation, DVec3::ONE),
    ]
}

fn blender_child(mode: InheritMode, child_animated: bool) -> DMat4 {
    // The rest pose (Blender's offset O) is the unanimated case; the animation adds the channel C.
    let skeleton = chain(&blender_case(false));
    let mut pose = ModelPose::default();
    Hierarchy::new(&skeleton, &[InheritMode::Full, mode]).unwrap().evaluate(&blender_case(child_animated), &mut pose);
    pose.model[1]
}

#[test]
fn blender_modes_that_drop_parent_shear_never_shear() {
    for mode in [InheritMode::BlenderAligned, InheritMode::BlenderAverage, InheritMode::BlenderNone] {
        for animated in [false, true] {
            assert!(shear_deg(&linear(&blender_child(mode, animated))) < 1e-9, "{mode} animated: {animated}");
        }
    }
    assert!(shear_deg(&linear(&blender_child(InheritMode::Full, true))) > 1.0, "the case does shear under full");
}

#[test]
fn blender_fix_shear_removes_rest_shear_only() {
    // Fix Shear orthogonalises P·O, the child's rest orientation: no shear at rest, but the child's own
    // rotation re-creates it (Blender D5588).
    assert!(shear_deg(&linear(&blender_child(InheritMode::BlenderFixShear, false))) < 1e-9);
    assert!(shear_deg(&linear(&blender_child(InheritMode::BlenderFixShear, true))) > 1.0);
    // Volume is kept: the determinant equals full inheritance's.
    let (fixed, full) = (blender_child(InheritMode::BlenderFixShear, true), blender_child(InheritMode::Full, true));
    assert!((fixed.determinant() - full.determinant()).abs() < 1e-12);
}

#[test]
fn blender_heads_follow_the_full_parent_matrix() {
    // In every Blender mode the bone's head is P·O·c: here the parent's matrix applied to the offset (0, 1, 0).
    let head = blender_child(InheritMode::Full, true).w_axis;
    for mode in InheritMode::ALL.iter().copied().filter(|m| m.is_blender()) {
        assert!(blender_child(mode, true).w_axis.abs_diff_eq(head, 1e-12), "{mode}");
    }
}

#[test]
fn blender_none_legacy_keeps_the_parent_shear_and_drops_its_scale() {
    // A sheared grandparent chain: root scaled, middle turned (so it shears), child under None (Legacy).
    let locals = [
        Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(2.0, 1.0, 1.0)),
        Transform::from_trs(DVec3::Y, DQuat::from_rotation_z(0.6), DVec3::ONE),
        Transform::from_trs(DVec3::Y, DQuat::IDENTITY, DVec3::ONE),
    ];
    let w = evaluate(&locals, &[InheritMode::Full, InheritMode::Full, InheritMode::BlenderNoneLegacy]);
    // The parent's columns are normalised but not orthogonalised: same angles, unit lengths.
    assert!((shear_deg(&linear(&w[2])) - shear_deg(&linear(&w[1]))).abs() < 1e-9);
    for column in [w[2].x_axis, w[2].y_axis, w[2].z_axis] {
        assert!((column.truncate().length() - 1.0).abs() < 1e-12);
    }
}
