//! Additive layers: a clip stored as its difference from a reference pose, added on top of another.
//!
//! Rotations do not commute, so the order matters: **local** order `q_base · q_add` turns the bone in its own
//! frame (what engines do), **global** order `q_add · q_base` turns it in its parent's frame (3ds Max CAT). The
//! difference is taken in the same order, so adding it to the reference gives the additive clip back. Translation
//! and scale follow ACL's `additive0`: translations add, scales multiply. The base's stretch rotation is kept.

use glam::{DQuat, DVec3};

use crate::math::slerp;
use crate::model::{Choice, Transform};

/// The pose the additive clip is the difference from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AdditiveReference {
    /// The additive clip's own first frame (at t = 0).
    #[default]
    First,
    /// The skeleton's rest pose.
    Rest,
}

impl Choice for AdditiveReference {
    const ALL: &'static [AdditiveReference] = &[AdditiveReference::First, AdditiveReference::Rest];

    fn id(self) -> &'static str {
        match self {
            AdditiveReference::First => "first",
            AdditiveReference::Rest => "rest",
        }
    }

    fn description(self) -> &'static str {
        match self {
            AdditiveReference::First => "the additive clip's own first frame (at t = 0)",
            AdditiveReference::Rest => "the skeleton's rest pose",
        }
    }
}

/// The side of the base rotation the additive rotation goes on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AdditiveOrder {
    /// `q_base · q_add`: in the bone's own frame.
    #[default]
    Local,
    /// `q_add · q_base`: in the parent's frame.
    Global,
}

impl Choice for AdditiveOrder {
    const ALL: &'static [AdditiveOrder] = &[AdditiveOrder::Local, AdditiveOrder::Global];

    fn id(self) -> &'static str {
        match self {
            AdditiveOrder::Local => "local",
            AdditiveOrder::Global => "global",
        }
    }

    fn description(self) -> &'static str {
        match self {
            AdditiveOrder::Local => "q_base · q_add: in the bone's own frame",
            AdditiveOrder::Global => "q_add · q_base: in the parent's frame",
        }
    }
}

/// What `sample` adds to `reference`: rotation `q_ref⁻¹·q` (local) or `q·q_ref⁻¹` (global), translation
/// `t − t_ref`, scale `s / s_ref` (1 where the reference's is 0: a collapsed axis says nothing about the ratio).
pub fn difference(sample: &Transform, reference: &Transform, order: AdditiveOrder) -> Transform {
    let inverse = reference.rotation.inverse();
    let rotation = match order {
        AdditiveOrder::Local => inverse * sample.rotation,
        AdditiveOrder::Global => sample.rotation * inverse,
    };
    let nonzero = reference.scale.cmpne(DVec3::ZERO);
    let scale = DVec3::select(nonzero, sample.scale / reference.scale, DVec3::ONE);
    Transform::from_trs(sample.translation - reference.translation, rotation, scale)
}

/// `base` plus `delta` at weight `w` in `[0, 1]`: rotation `q_base·Δq^w` or `Δq^w·q_base` (`Δq^w` by slerp from the
/// identity), translation `t_base + w·Δt`, scale `s_base ⊙ lerp(1, Δs, w)`.
pub fn add(base: &Transform, delta: &Transform, w: f64, order: AdditiveOrder) -> Transform {
    let turn = if w == 1.0 { delta.rotation } else { slerp(DQuat::IDENTITY, delta.rotation, w) };
    let rotation = match order {
        AdditiveOrder::Local => base.rotation * turn,
        AdditiveOrder::Global => turn * base.rotation,
    };
    Transform {
        translation: base.translation + delta.translation * w,
        rotation,
        scale: base.scale * DVec3::ONE.lerp(delta.scale, w),
        stretch: base.stretch,
    }
}

/// Adds, bone by bone, the difference of `sample` from `reference` to `pose` at weight `w` (clamped). Bones where
/// the sample equals the reference (the clip leaves them alone) are skipped.
pub fn add_poses(pose: &mut [Transform], sample: &[Transform], reference: &[Transform], w: f64, order: AdditiveOrder) {
    let w = super::unit_weight(w);
    if w == 0.0 {
        return;
    }
    for ((base, sample), reference) in pose.iter_mut().zip(sample).zip(reference) {
        if sample != reference {
            *base = add(base, &difference(sample, reference, order), w, order);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use super::*;

    #[test]
    fn local_and_global_order_differ_by_a_known_rotation() {
        // Base: 90° about Z. Additive: 90° about X (reference: identity).
        // Local:  Rz·Rx takes Y to Rz·(Rx·Y) = Rz·Z = Z.
        // Global: Rx·Rz takes Y to Rx·(Rz·Y) = Rx·(−X) = −X.
        // They differ by Rz·Rx·Rz⁻¹ (= 90° about Rz·X = Y) against Rx: local = Ry·Rz, global = Rx·Rz.
        let base = Transform::from_trs(DVec3::ZERO, DQuat::from_rotation_z(FRAC_PI_2), DVec3::ONE);
        let sample = Transform::from_trs(DVec3::ZERO, DQuat::from_rotation_x(FRAC_PI_2), DVec3::ONE);
        let reference = Transform::IDENTITY;
        let local = add(&base, &difference(&sample, &reference, AdditiveOrder::Local), 1.0, AdditiveOrder::Local);
        let global = add(&base, &difference(&sample, &reference, AdditiveOrder::Global), 1.0, AdditiveOrder::Global);
        assert!((local.rotation * DVec3::Y).abs_diff_eq(DVec3::Z, 1e-15));
        assert!((global.rotation * DVec3::Y).abs_diff_eq(-DVec3::X, 1e-15));
        let rz = DQuat::from_rotation_z(FRAC_PI_2);
        assert!(local.rotation.abs_diff_eq(DQuat::from_rotation_y(FRAC_PI_2) * rz, 1e-15));
        assert!(global.rotation.abs_diff_eq(DQuat::from_rotation_x(FRAC_PI_2) * rz, 1e-15));
        // local = (Ry·Rx⁻¹)·global: the two orders differ by a 120° turn (Ry·Rx⁻¹ has w = cos²45° = ½).
        let between = local.rotation * global.rotation.inverse();
        assert!((crate::math::quat_angle(between).to_degrees() - 120.0).abs() < 1e-12);
    }

    #[test]
    fn adding_the_difference_to_the_reference_gives_the_sample_back() {
        let reference = Transform::from_trs(
            DVec3::new(1.0, 2.0, 3.0),
            DQuat::from_rotation_y(0.3) * DQuat::from_rotation_x(0.2),
            DVec3::new(1.0, 2.0, 0.5),
        );
        let sample = Transform::from_trs(
            DVec3::new(0.0, 2.5, 3.0),
            DQuat::from_rotation_z(-0.7) * DQuat::from_rotation_x(0.4),
            DVec3::new(2.0, 2.0, 1.0),
        );
        for order in [AdditiveOrder::Local, AdditiveOrder::Global] {
            let back = add(&reference, &difference(&sample, &reference, order), 1.0, order);
            assert!(back.translation.abs_diff_eq(sample.translation, 1e-15));
            assert!(back.rotation.abs_diff_eq(sample.rotation, 1e-15));
            assert!(back.scale.abs_diff_eq(sample.scale, 1e-15));
        }
    }

    #[test]
    fn weights_scale_each_part_as_acl_additive0() {
        // Δt = (2, 0, 0), Δs = (3, 1, 1), Δq = 1 rad about X; at w = 0.5 on an identity base:
        // t = (1, 0, 0), s = lerp(1, 3, 0.5) = 2 in X, rotation 0.5 rad.
        let delta =
            Transform::from_trs(DVec3::new(2.0, 0.0, 0.0), DQuat::from_rotation_x(1.0), DVec3::new(3.0, 1.0, 1.0));
        let half = add(&Transform::IDENTITY, &delta, 0.5, AdditiveOrder::Local);
        assert_eq!(half.translation, DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(half.scale, DVec3::new(2.0, 1.0, 1.0));
        assert!(half.rotation.abs_diff_eq(DQuat::from_rotation_x(0.5), 1e-15));
        // A zero reference scale adds nothing to that axis.
        let collapsed = Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(0.0, 1.0, 1.0));
        let d = difference(&Transform::IDENTITY, &collapsed, AdditiveOrder::Local);
        assert_eq!(d.scale, DVec3::ONE);
    }
}
