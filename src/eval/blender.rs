//! Blender's bone scale-inheritance modes (a bone's "Inherit Scale" option), evaluated in `f64`.
//!
//! # The Blender bone model
//!
//! Blender builds a pose bone's pose matrix (armature space) from three matrices:
//!
//! - `P`, the parent's pose matrix;
//! - `O`, the bone's rest offset in the parent's frame (`BKE_bone_offset_matrix_get`): the rest
//!   rotation `bone_mat` with translation `head + (0, parent length, 0)`, no scale;
//! - `C`, the channel matrix `T(loc)·R(rot)·S(scale)`: the animated transform relative to the rest.
//!
//! `BKE_bone_parent_transform_calc_from_matrices` (`source/blender/blenkernel/intern/armature.cc`)
//! turns `P` and `O` into a parent transform: a `rotscale` matrix that the channel's rotation and
//! scale go through, a `loc` matrix for the channel's translation and a per-axis `post_scale`.
//! `BKE_bone_parent_transform_apply` then gives
//!
//! ```text
//! pose = rotscale·C, with its translation replaced by loc·c (c = C's translation, as a point),
//!        then its three axis columns multiplied by post_scale (rescale_m4)
//! ```
//!
//! With Inherit Rotation on and Local Location on, the only case handled here, `loc = P·O` in every
//! mode (so the bone's head always follows the parent's full matrix) and
//!
//! | mode       | `rotscale`                            | `post_scale`                     |
//! |------------|---------------------------------------|----------------------------------|
//! | Full       | `P·O`                                 | 1                                |
//! | FixShear   | `ortho(P·O)`                          | 1                                |
//! | Aligned    | `unit(ortho(P))·O`                    | the column lengths of `ortho(P)` |
//! | Average    | `orthonormal(P)·cbrt(abs(det P₃))·O`  | 1                                |
//! | None       | `orthonormal(P)·O`                    | 1                                |
//! | NoneLegacy | `unit(P)·O`                           | 1                                |
//!
//! `ortho` and `orthonormal` are `orthogonalize_m4_stable(m, 1, false)` and `(m, 1, true)` from
//! `source/blender/blenlib/intern/math_matrix.cc`: bone Y is the primary axis, see
//! `orthogonalize_stable` below. `unit` is `normalize_m4` / `normalize_m4_ex` (every axis column
//! scaled to unit length, shear kept) and `det P₃` is `mat4_to_volume_scale`. All of them touch the
//! 3×3 part only; the translation of `rotscale` never matters, `apply` replaces it.
//!
//! Full is therefore exactly `P·O·C`. Full, FixShear, Aligned and Average keep the volume change:
//! the pose's determinant is `det(P₃·O₃·C₃)` (`ortho` keeps the determinant); None and NoneLegacy
//! drop it. Aligned, Average and None never shear the child (up to the dead band below); FixShear
//! only removes the shear of the child's rest orientation; NoneLegacy keeps the parent's shear.
//!
//! Blender's thresholds (the shear dead band of `orthogonalize_stable`, the shortest vector
//! `normalize_v3` accepts) are kept so that the same branches are taken; the arithmetic is `f64`.
//! Matrices are assumed affine (bottom row `0 0 0 1`), as Blender's armature code does.

use std::f64::consts::FRAC_PI_2;

use glam::{DMat3, DMat4, DVec3};

use crate::model::InheritMode;

/// A bone's Inherit Scale option (`Bone.inherit_scale_mode`, Blender's `BONE_INHERIT_SCALE_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlenderInherit {
    /// Inherit all effects of the parent's scale and shear: `P·O·C`.
    Full,
    /// Inherit the parent's scale, but remove the child's shear in its rest orientation, keeping
    /// the volume.
    FixShear,
    /// Apply the parent's scale along the child's own axes: parent X scale to child X, and so on.
    Aligned,
    /// Inherit one uniform scale: the cube root of the parent's volume change.
    Average,
    /// Ignore the parent's scale and shear.
    None,
    /// Ignore the parent's scale but keep its shear (Blender before 2.81).
    NoneLegacy,
}

impl BlenderInherit {
    /// The Blender mode behind one of bonescope's Blender inheritance modes.
    pub fn from_mode(mode: InheritMode) -> Option<Self> {
        Some(match mode {
            InheritMode::BlenderFixShear => BlenderInherit::FixShear,
            InheritMode::BlenderAligned => BlenderInherit::Aligned,
            InheritMode::BlenderAverage => BlenderInherit::Average,
            InheritMode::BlenderNone => BlenderInherit::None,
            InheritMode::BlenderNoneLegacy => BlenderInherit::NoneLegacy,
            _ => return None,
        })
    }
}

/// `orthogonalize_stable` leaves the two secondary axes as they are when the cosine of their angle
/// is at most this: no significant shear.
const SHEAR_COS_MIN: f64 = 1e-4;

/// ... or at least this: the axes are parallel, there is no plane to turn them in
/// (`1 − FLT_EPSILON`).
const SHEAR_COS_MAX: f64 = 1.0 - f32::EPSILON as f64;

/// Squared length at or below which Blender's `normalize_v3` gives the zero vector.
const NORMALIZE_MIN_LENGTH_SQ: f64 = 1e-35;

/// Blender's `BKE_bone_parent_transform_calc_from_matrices` + `BKE_bone_parent_transform_apply` for
/// a bone with Inherit Rotation on and Local Location on: the bone's pose (model) matrix from its
/// parent's pose matrix `parent` (P), its rest offset `offset` (O: rest translation+rotation
/// relative to the parent, no scale) and its channel matrix `channel` (C = T(loc)·R(rot)·S(scale),
/// the animated local relative to the rest).
pub fn child_pose(mode: BlenderInherit, parent: &DMat4, offset: &DMat4, channel: &DMat4) -> DMat4 {
    let (rotscale, post_scale) = parent_rotscale(mode, parent, offset);
    let loc = *parent * *offset;
    apply_parent_transform(&rotscale, &loc, post_scale, channel)
}

/// The `rotscale_mat` and `post_scale` parts of `BKE_bone_parent_transform_calc_from_matrices`,
/// with Inherit Rotation on.
fn parent_rotscale(mode: BlenderInherit, parent: &DMat4, offset: &DMat4) -> (DMat4, DVec3) {
    let no_post_scale = DVec3::ONE;
    match mode {
        BlenderInherit::Full => (*parent * *offset, no_post_scale),
        BlenderInherit::FixShear => (orthogonalize_y(*parent * *offset, false), no_post_scale),
        BlenderInherit::Aligned => {
            let (axes, lengths) = normalize_axes(orthogonalize_y(*parent, false));
            (axes * *offset, lengths)
        }
        BlenderInherit::Average => {
            let average_scale = volume_scale(parent).abs().cbrt();
            let rotation = orthogonalize_y(*parent, true);
            let scaled = with_linear(rotation, linear(rotation) * average_scale);
            (scaled * *offset, no_post_scale)
        }
        BlenderInherit::None => (orthogonalize_y(*parent, true) * *offset, no_post_scale),
        BlenderInherit::NoneLegacy => (normalize_axes(*parent).0 * *offset, no_post_scale),
    }
}

/// `BKE_bone_parent_transform_apply`: `rotscale·C`, translated to `loc·c`, axes times `post_scale`.
fn apply_parent_transform(rotscale: &DMat4, loc: &DMat4, post_scale: DVec3, channel: &DMat4) -> DMat4 {
    let mut pose = *rotscale * *channel;
    let head = loc.transform_point3(channel.w_axis.truncate());
    pose.w_axis = head.extend(pose.w_axis.w);
    pose.x_axis *= post_scale.x;
    pose.y_axis *= post_scale.y;
    pose.z_axis *= post_scale.z;
    pose
}

/// `mat4_to_volume_scale`: the determinant of the 3×3 part.
fn volume_scale(m: &DMat4) -> f64 {
    linear(*m).determinant()
}

/// The 3×3 (rotation, scale and shear) part of an affine matrix.
fn linear(m: DMat4) -> DMat3 {
    DMat3::from_mat4(m)
}

/// `m` with its 3×3 part replaced by `linear`, its translation kept.
fn with_linear(m: DMat4, linear: DMat3) -> DMat4 {
    DMat4::from_cols(linear.x_axis.extend(0.0), linear.y_axis.extend(0.0), linear.z_axis.extend(0.0), m.w_axis)
}

/// `orthogonalize_m4_stable(m, 1, normalize)`: `orthogonalize_stable` on the axis columns with bone
/// Y primary, then X, then Z.
fn orthogonalize_y(m: DMat4, normalize: bool) -> DMat4 {
    let axes = linear(m);
    let [y, x, z] = orthogonalize_stable(axes.y_axis, axes.x_axis, axes.z_axis, normalize);
    with_linear(m, DMat3::from_cols(x, y, z))
}

/// `normalize_m4_ex`: every axis column scaled to unit length (shear kept), and the lengths.
fn normalize_axes(m: DMat4) -> (DMat4, DVec3) {
    let axes = linear(m);
    let (x, x_length) = unit_and_length(axes.x_axis);
    let (y, y_length) = unit_and_length(axes.y_axis);
    let (z, z_length) = unit_and_length(axes.z_axis);
    (with_linear(m, DMat3::from_cols(x, y, z)), DVec3::new(x_length, y_length, z_length))
}

/// `normalize_v3_v3`: the unit vector along `v` and the length of `v`, or zero and 0 for a vector
/// too short (or not finite) to normalise.
fn unit_and_length(v: DVec3) -> (DVec3, f64) {
    let length_sq = v.length_squared();
    if length_sq > NORMALIZE_MIN_LENGTH_SQ {
        let length = length_sq.sqrt();
        (v / length, length)
    } else {
        (DVec3::ZERO, 0.0)
    }
}

/// Blender's `orthogonalize_stable(v1, v2, v3, normalize)`: makes `second` and `third` orthogonal
/// to `primary` and to each other, treating the two alike. Returns `[primary, second, third]`.
///
/// 1. The `primary` components of `second` and `third` are removed. That is a shear along
///    `primary`, so the determinant is kept; `primary` itself is never turned.
/// 2. If the two are then still sheared (`1e-4 < |cos| < 1 − FLT_EPSILON`), each turns by half the
///    gap to 90° in their common plane, and both are scaled by `√sin(angle)`: the area of their
///    parallelogram, and with it the determinant, is kept. Below the dead band a small shear
///    stays.
///
/// With `normalize` all three come out unit length instead (a rotation or a mirrored one, up to the
/// dead band).
fn orthogonalize_stable(primary: DVec3, second: DVec3, third: DVec3, normalize: bool) -> [DVec3; 3] {
    let [primary, second, third] = remove_primary_component(primary, second, third, normalize);
    let (second_dir, second_length) = unit_and_length(second);
    let (third_dir, third_length) = unit_and_length(third);
    let cos_angle = second_dir.dot(third_dir);
    let sheared = SHEAR_COS_MIN < cos_angle.abs() && cos_angle.abs() < SHEAR_COS_MAX;
    match (sheared, normalize) {
        (false, false) => [primary, second, third],
        (false, true) => [primary, second_dir, third_dir],
        (true, normalize) => {
            let angle = cos_angle.acos();
            let (second_dir, third_dir) = turn_to_right_angle(second_dir, third_dir, angle);
            if normalize {
                [primary, second_dir, third_dir]
            } else {
                let area_keeping = angle.sin().sqrt();
                [primary, second_dir * (second_length * area_keeping), third_dir * (third_length * area_keeping)]
            }
        }
    }
}

/// Step 1 of `orthogonalize_stable`: `second` and `third` projected onto the plane orthogonal to
/// `primary`, and `primary` made unit length when normalising. A zero `primary` changes nothing.
fn remove_primary_component(primary: DVec3, second: DVec3, third: DVec3, normalize: bool) -> [DVec3; 3] {
    let length_sq = primary.length_squared();
    if length_sq > 0.0 {
        let reject = |v: DVec3| v - primary * (v.dot(primary) / length_sq);
        let primary = if normalize { primary / length_sq.sqrt() } else { primary };
        [primary, reject(second), reject(third)]
    } else {
        [primary, second, third]
    }
}

/// Turns the unit vectors `a` and `b`, at `angle` (strictly between 0 and π) from each other, in
/// their common plane, each by half of `π/2 − angle` (apart when acute, together when obtuse), so
/// that they end up orthogonal. Returns the new unit vectors.
fn turn_to_right_angle(a: DVec3, b: DVec3, angle: f64) -> (DVec3, DVec3) {
    let target_angle = (angle + FRAC_PI_2) / 2.0;
    let a_across_b = (a - b * a.dot(b)).normalize();
    let a = a_across_b * target_angle.sin() + b * target_angle.cos();
    let b = (b - a * b.dot(a)).normalize();
    (a, b)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_8, SQRT_2};

    use glam::DQuat;

    use super::*;

    /// Absolute tolerance for results of O(1) size: every expected value below is a short closed
    /// form of a few literal entries, so f64 rounding stays within a few ulps (~1e-15).
    const EPS: f64 = 1e-12;

    const ALL: [BlenderInherit; 6] = [
        BlenderInherit::Full,
        BlenderInherit::FixShear,
        BlenderInherit::Aligned,
        BlenderInherit::Average,
        BlenderInherit::None,
        BlenderInherit::NoneLegacy,
    ];

    /// An affine matrix from its three axis columns and its translation.
    fn affine(x: [f64; 3], y: [f64; 3], z: [f64; 3], t: [f64; 3]) -> DMat4 {
        DMat4::from_cols(
            DVec3::from(x).extend(0.0),
            DVec3::from(y).extend(0.0),
            DVec3::from(z).extend(0.0),
            DVec3::from(t).extend(1.0),
        )
    }

    fn assert_near(actual: DMat4, expected: DMat4, what: &str) {
        assert!(actual.abs_diff_eq(expected, EPS), "{what}:\n  actual   {actual:.15}\n  expected {expected:.15}");
    }

    fn assert_vec_near(actual: DVec3, expected: DVec3, what: &str) {
        assert!(actual.abs_diff_eq(expected, EPS), "{what}: actual {actual:.15}, expected {expected:.15}");
    }

    /// `P = T(1, 2, 3)·Rz(90°)·diag(2, 1, 4)`: non-uniform scale, rotated, no shear; `det P₃ = 8`.
    /// `Rz(90°)` maps x→y, y→−x, so the columns are `(0, 2, 0)`, `(−1, 0, 0)`, `(0, 0, 4)`.
    fn scaled_parent() -> DMat4 {
        affine([0.0, 2.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 4.0], [1.0, 2.0, 3.0])
    }

    /// `O = T(0, 1, 0)·Rz(θ)` with `cos θ = 0.8`, `sin θ = 0.6`: the child sits at the parent's
    /// tail (parent length 1), turned about Z.
    fn offset() -> DMat4 {
        affine([0.8, 0.6, 0.0], [-0.6, 0.8, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0])
    }

    /// `C = T(0.5, 0, 0)·Rx(90°)`: x→x, y→z, z→−y. No scale.
    fn channel() -> DMat4 {
        affine([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [0.5, 0.0, 0.0])
    }

    /// The head of [`child_pose`] with the fixtures above, in every mode: `P·O·c` with
    /// `c = (0.5, 0, 0)`. `O·c = (0.4, 0.3, 0) + (0, 1, 0) = (0.4, 1.3, 0)`;
    /// `P₃·(0.4, 1.3, 0) = (−1.3, 0.8, 0)`; plus `(1, 2, 3)`.
    const HEAD: [f64; 3] = [-0.3, 2.8, 3.0];

    /// Hand derivation for the fixtures. `S·R_o` (`S = diag(2, 1, 4)`) has the columns
    /// `(1.6, 0.6, 0)`, `(−1.2, 0.8, 0)`, `(0, 0, 4)`, so `P₃·O₃ = Rz(90°)·S·R_o` has
    /// `(−0.6, 1.6, 0)`, `(−0.8, −1.2, 0)`, `(0, 0, 4)`. `C₃` (Rx 90°) takes column x, then z, then
    /// −y of what it multiplies.
    #[test]
    fn full_by_hand() {
        let expected = affine([-0.6, 1.6, 0.0], [0.0, 0.0, 4.0], [0.8, 1.2, 0.0], HEAD);
        let pose = child_pose(BlenderInherit::Full, &scaled_parent(), &offset(), &channel());
        assert_near(pose, expected, "Full");
    }

    /// `ortho(P·O)`, in the parent's rotated frame (it commutes with rotations): the primary
    /// `Y = (−1.2, 0.8, 0)` (`|Y|² = 2.08`) stays; `X = (1.6, 0.6, 0)` loses its Y part,
    /// `X·Y = −1.44`: `X' = X + (1.44 / 2.08)·Y = (10/13, 15/13, 0)`; `Z` is already orthogonal to
    /// both, so no turn. `Rz(90°)`: `X' = (−15/13, 10/13, 0)`, `Y = (−0.8, −1.2, 0)`,
    /// `Z = (0, 0, 4)`; then `C₃`. `det = 4·((−15/13)(−1.2) − (10/13)(−0.8)) = 8 = det(P₃·O₃)`.
    #[test]
    fn fix_shear_by_hand() {
        let expected = affine([-15.0 / 13.0, 10.0 / 13.0, 0.0], [0.0, 0.0, 4.0], [0.8, 1.2, 0.0], HEAD);
        let pose = child_pose(BlenderInherit::FixShear, &scaled_parent(), &offset(), &channel());
        assert_near(pose, expected, "FixShear");
    }

    /// The rotation `Rz(90°)·R_o·C₃ = Rz(90° + θ)·Rx(90°)`: `Rz(90° + θ)` has the columns
    /// `(−0.6, 0.8, 0)`, `(−0.8, −0.6, 0)`, `(0, 0, 1)`, so the product has `(−0.6, 0.8, 0)`,
    /// `(0, 0, 1)`, `(0.8, 0.6, 0)`.
    const ROTATION: [[f64; 3]; 3] = [[-0.6, 0.8, 0.0], [0.0, 0.0, 1.0], [0.8, 0.6, 0.0]];

    fn rotation_scaled(scale: [f64; 3]) -> DMat4 {
        let [x, y, z] = ROTATION;
        let axis = |v: [f64; 3], s: f64| v.map(|c| c * s);
        affine(axis(x, scale[0]), axis(y, scale[1]), axis(z, scale[2]), HEAD)
    }

    /// `ortho(P) = P` (no shear), `unit(P) = Rz(90°)` and `post_scale = (2, 1, 4)`, applied along
    /// the child's own axes: `Rz(90°)·R_o·C₃·diag(2, 1, 4)`.
    #[test]
    fn aligned_by_hand() {
        let pose = child_pose(BlenderInherit::Aligned, &scaled_parent(), &offset(), &channel());
        assert_near(pose, rotation_scaled([2.0, 1.0, 4.0]), "Aligned");
    }

    /// `orthonormal(P) = Rz(90°)`, times `cbrt(8) = 2`.
    #[test]
    fn average_by_hand() {
        let pose = child_pose(BlenderInherit::Average, &scaled_parent(), &offset(), &channel());
        assert_near(pose, rotation_scaled([2.0; 3]), "Average");
    }

    /// `orthonormal(P) = unit(P) = Rz(90°)` for a parent without shear: the scale is dropped.
    #[test]
    fn none_and_none_legacy_by_hand() {
        for mode in [BlenderInherit::None, BlenderInherit::NoneLegacy] {
            let pose = child_pose(mode, &scaled_parent(), &offset(), &channel());
            assert_near(pose, rotation_scaled([1.0; 3]), &format!("{mode:?}"));
        }
    }

    /// A parent whose Y leans 45° towards X (columns `(1, 0, 0)`, `(1, 1, 0)`, `(0, 0, 1)`,
    /// `det = 1`), with `O = C = I`, so the pose is the modified parent itself.
    /// `ortho(P)`: Y stays, `X' = X − ½·Y = (½, −½, 0)`, Z is orthogonal to both.
    /// `orthonormal(P)`: `(1/√2, −1/√2, 0)`, `(1/√2, 1/√2, 0)`, `(0, 0, 1)`; `unit(P)` keeps the
    /// 45° between X and Y.
    #[test]
    fn sheared_parent_by_hand() {
        let h = FRAC_1_SQRT_2;
        let parent = affine([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0; 3]);
        let ortho = affine([0.5, -0.5, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0; 3]);
        let orthonormal = affine([h, -h, 0.0], [h, h, 0.0], [0.0, 0.0, 1.0], [0.0; 3]);
        let unit = affine([1.0, 0.0, 0.0], [h, h, 0.0], [0.0, 0.0, 1.0], [0.0; 3]);
        let cases = [
            (BlenderInherit::Full, parent),
            (BlenderInherit::FixShear, ortho),
            // unit(ortho(P))·diag(|X'|, |Y|, |Z|) = ortho(P).
            (BlenderInherit::Aligned, ortho),
            // det P₃ = 1.
            (BlenderInherit::Average, orthonormal),
            (BlenderInherit::None, orthonormal),
            (BlenderInherit::NoneLegacy, unit),
        ];
        for (mode, expected) in cases {
            let pose = child_pose(mode, &parent, &DMat4::IDENTITY, &DMat4::IDENTITY);
            assert_near(pose, expected, &format!("{mode:?}"));
        }
    }

    /// A rotation about a skew axis, with a translation.
    fn rigid(axis: DVec3, angle: f64, translation: DVec3) -> DMat4 {
        DMat4::from_rotation_translation(DQuat::from_axis_angle(axis.normalize(), angle), translation)
    }

    /// Parents for the invariants: non-uniform scale, shear in the X–Y plane (Y leaning), shear in
    /// the X–Z plane (what the symmetric turn of `orthogonalize_stable` fixes), and a mirrored one.
    fn parents() -> Vec<DMat4> {
        let frame = rigid(DVec3::new(1.0, 2.0, -0.5), 0.7, DVec3::new(0.3, -1.0, 2.0));
        let shear_xy = affine([1.0, 0.2, 0.0], [0.6, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0; 3]);
        let shear_xz = affine([1.0, 0.0, 0.4], [0.0, 1.0, 0.0], [0.7, 0.0, 1.0], [0.0; 3]);
        let scale = DMat4::from_scale(DVec3::new(2.0, 0.7, 1.3));
        let mirror = DMat4::from_scale(DVec3::new(1.5, -0.8, 1.1));
        vec![frame * scale, frame * shear_xy * scale, frame * shear_xz * scale, frame * shear_xy * shear_xz * mirror]
    }

    fn skew_offset() -> DMat4 {
        rigid(DVec3::new(-0.3, 0.5, 1.0), 1.1, DVec3::new(0.1, 1.4, -0.2))
    }

    /// A channel with a rotation, a non-uniform scale and a translation.
    fn scaled_channel() -> DMat4 {
        DMat4::from_scale_rotation_translation(
            DVec3::new(1.2, 0.5, 2.0),
            DQuat::from_axis_angle(DVec3::new(0.6, -0.8, 0.0), 0.9),
            DVec3::new(0.25, -0.5, 0.75),
        )
    }

    /// Cosine of the angle between two vectors.
    fn cos_between(a: DVec3, b: DVec3) -> f64 {
        a.dot(b) / (a.length() * b.length())
    }

    /// The largest |cos| between two axis columns: 0 for a matrix without shear.
    fn max_shear_cos(m: DMat4) -> f64 {
        let m = linear(m);
        let (x, y, z) = (m.x_axis, m.y_axis, m.z_axis);
        [cos_between(x, y), cos_between(x, z), cos_between(y, z)].into_iter().fold(0.0, |worst, c| worst.max(c.abs()))
    }

    #[test]
    fn full_is_exactly_the_matrix_product() {
        let cases = [(scaled_parent(), offset(), channel())]
            .into_iter()
            .chain(parents().into_iter().map(|parent| (parent, skew_offset(), scaled_channel())));
        for (parent, offset, channel) in cases {
            let pose = child_pose(BlenderInherit::Full, &parent, &offset, &channel);
            assert_eq!(pose, parent * offset * channel);
        }
    }

    /// `loc = P·O` in every mode, and `post_scale` only touches the axes.
    #[test]
    fn head_follows_the_full_parent_matrix_in_every_mode() {
        let (offset, channel) = (skew_offset(), scaled_channel());
        for parent in parents() {
            let expected = (parent * offset).transform_point3(channel.w_axis.truncate());
            for mode in ALL {
                let pose = child_pose(mode, &parent, &offset, &channel);
                assert_vec_near(pose.w_axis.truncate(), expected, &format!("{mode:?}"));
            }
        }
    }

    /// For `P = T·R·s` (uniform `s ≠ 0`): `ortho` changes nothing, `unit(s·R) = sign(s)·R`, and
    /// Aligned's `post_scale = (|s|, |s|, |s|)` commutes with everything, Average's factor is
    /// `cbrt(|s|³) = |s|`. So Full, FixShear, Aligned and Average all give `P·O·C`, while None and
    /// NoneLegacy give it with the 3×3 part divided by `|s|`: `T(P·O·c)·sign(s)·R·O₃·C₃`.
    #[test]
    fn uniform_parent_scale() {
        let (offset, channel) = (skew_offset(), scaled_channel());
        for s in [1.5, -0.5] {
            let parent =
                rigid(DVec3::new(1.0, -1.0, 0.5), 2.0, DVec3::new(1.0, 2.0, 3.0)) * DMat4::from_scale(DVec3::splat(s));
            let full = parent * offset * channel;
            let unscaled = with_linear(full, linear(full) * s.abs().recip());
            for mode in ALL {
                let expected = match mode {
                    BlenderInherit::None | BlenderInherit::NoneLegacy => unscaled,
                    _ => full,
                };
                let pose = child_pose(mode, &parent, &offset, &channel);
                assert_near(pose, expected, &format!("{mode:?}, s = {s}"));
            }
        }
    }

    /// Aligned, Average and None give the child orthogonal axes whatever the parent's scale and
    /// shear (shear above the 1e-4 dead band), even with a non-uniformly scaled channel: they hand
    /// the channel an orthonormal frame and scale only along the child's own axes. Tolerance 1e-12
    /// on the cosines.
    #[test]
    fn aligned_average_none_never_shear() {
        let (offset, channel) = (skew_offset(), scaled_channel());
        for parent in parents() {
            assert!(max_shear_cos(parent * offset * channel) > 0.01, "Full must shear here");
            for mode in [BlenderInherit::Aligned, BlenderInherit::Average, BlenderInherit::None] {
                let pose = child_pose(mode, &parent, &offset, &channel);
                assert!(max_shear_cos(pose) < EPS, "{mode:?}: {}", max_shear_cos(pose));
            }
        }
    }

    /// NoneLegacy only rescales the parent's columns: with a rest child the angles between the axes
    /// are the parent's.
    #[test]
    fn none_legacy_keeps_the_parent_shear() {
        let at_rest = DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0));
        for parent in parents() {
            let pose = child_pose(BlenderInherit::NoneLegacy, &parent, &at_rest, &DMat4::IDENTITY);
            let (p, q) = (linear(parent), linear(pose));
            for (a, b) in [(0, 1), (0, 2), (1, 2)] {
                let expected = cos_between(p.col(a), p.col(b));
                assert!((cos_between(q.col(a), q.col(b)) - expected).abs() < EPS);
                assert!((q.col(a).length() - 1.0).abs() < EPS);
            }
        }
    }

    /// Whether two matrices have the same determinant (3×3 part), to 1e-12 relative.
    fn same_volume(a: &DMat4, b: &DMat4) -> bool {
        (volume_scale(a) / volume_scale(b) - 1.0).abs() < EPS
    }

    /// `det(ortho(M)) = det M`, `det(unit(M)) = det M / (column lengths)` and the Aligned
    /// post-scale multiplies those lengths back; Average's `cbrt(|det P₃|)³` restores `|det P₃|`
    /// and the unit frame keeps the sign. None and NoneLegacy do not (checked for the scaled
    /// parent, `det P₃ = 2·0.7·1.3`).
    #[test]
    fn volume_kept_except_by_none_modes() {
        let (offset, channel) = (skew_offset(), scaled_channel());
        for (i, parent) in parents().into_iter().enumerate() {
            let full = parent * offset * channel;
            for mode in ALL {
                let kept = same_volume(&child_pose(mode, &parent, &offset, &channel), &full);
                match mode {
                    BlenderInherit::None | BlenderInherit::NoneLegacy => assert!(i > 0 || !kept),
                    _ => assert!(kept, "{mode:?}, parent {i}"),
                }
            }
        }
    }

    /// What FixShear guarantees (`orthogonalize_m4_stable(P·O, 1, false)`, seen through a rest
    /// channel): the determinant of `P₃·O₃`, bone Y of `P·O`, and no shear, also under a channel
    /// that only scales along the bone's axes. A rotated child of a non-uniformly scaled parent
    /// still shears. Tolerances 1e-12, relative for the determinant.
    #[test]
    fn fix_shear_keeps_volume_and_bone_y() {
        let offset = skew_offset();
        let stretched = DMat4::from_scale(DVec3::new(1.2, 0.5, 2.0));
        for parent in parents() {
            let rest = child_pose(BlenderInherit::FixShear, &parent, &offset, &DMat4::IDENTITY);
            assert!(same_volume(&rest, &(parent * offset)));
            assert_vec_near(rest.y_axis.truncate(), (parent * offset).y_axis.truncate(), "bone Y");
            assert!(max_shear_cos(rest) < EPS, "rest: {}", max_shear_cos(rest));

            let pose = child_pose(BlenderInherit::FixShear, &parent, &offset, &stretched);
            assert!(max_shear_cos(pose) < EPS, "stretched: {}", max_shear_cos(pose));

            let channel = scaled_channel();
            let pose = child_pose(BlenderInherit::FixShear, &parent, &offset, &channel);
            assert!(max_shear_cos(pose) > 0.01, "turned: {}", max_shear_cos(pose));
        }
    }

    /// The secondary axes `(2, 1, 0)` and `(1, −0.5, 1)` around the primary `(0, 2, 0)`: without
    /// their Y parts they are `(2, 0, 0)` and `(1, 0, 1)`, 45° apart. Each turns 22.5° away from
    /// the other (to −π/8 and 3π/8 in the X–Z plane) and both lengths (2 and √2) are scaled by
    /// `√sin 45° = 2^(−1/4)`. `det` stays `X·(Y × Z) = 4`.
    #[test]
    fn orthogonalize_stable_by_hand() {
        let primary = DVec3::new(0.0, 2.0, 0.0);
        let (second, third) = (DVec3::new(2.0, 1.0, 0.0), DVec3::new(1.0, -0.5, 1.0));
        let in_xz = |angle: f64| DVec3::new(angle.cos(), 0.0, angle.sin());
        let k = 2f64.powf(-0.25);

        let [p, s, t] = orthogonalize_stable(primary, second, third, false);
        assert_eq!(p, primary);
        assert_vec_near(s, in_xz(-FRAC_PI_8) * (2.0 * k), "second");
        assert_vec_near(t, in_xz(3.0 * FRAC_PI_8) * (SQRT_2 * k), "third");

        let [p, s, t] = orthogonalize_stable(primary, second, third, true);
        assert_vec_near(p, DVec3::Y, "unit primary");
        assert_vec_near(s, in_xz(-FRAC_PI_8), "unit second");
        assert_vec_near(t, in_xz(3.0 * FRAC_PI_8), "unit third");
    }

    /// Primary direction unchanged, result orthogonal, determinant kept (or unit axes when
    /// normalising, determinant ±1 with the input's sign). Tolerances 1e-12, relative for the
    /// determinant.
    #[test]
    fn orthogonalize_stable_invariants() {
        let triples = [
            ([0.0, 2.0, 0.0], [2.0, 1.0, 0.0], [1.0, -0.5, 1.0]),
            ([0.3, 1.1, -0.2], [1.0, 0.4, 0.5], [0.2, -0.3, 0.9]),
            ([0.5, -1.0, 0.8], [-0.7, 0.2, 1.5], [1.2, 0.9, -0.4]),
            // Mirrored (negative determinant), the two secondaries at an obtuse angle.
            ([0.1, 1.0, 0.2], [0.9, 0.1, 0.3], [-1.0, 0.0, -0.4]),
        ];
        for (v1, v2, v3) in triples {
            let (v1, v2, v3) = (DVec3::from(v1), DVec3::from(v2), DVec3::from(v3));
            let det = |y: DVec3, x: DVec3, z: DVec3| DMat3::from_cols(x, y, z).determinant();
            let before = det(v1, v2, v3);

            let [p, s, t] = orthogonalize_stable(v1, v2, v3, false);
            assert_eq!(p, v1);
            for (a, b) in [(p, s), (p, t), (s, t)] {
                assert!(cos_between(a, b).abs() < EPS);
            }
            assert!((det(p, s, t) / before - 1.0).abs() < EPS);

            let [p, s, t] = orthogonalize_stable(v1, v2, v3, true);
            assert_vec_near(p, v1.normalize(), "unit primary");
            let m = DMat3::from_cols(s, p, t);
            assert!((m.transpose() * m).abs_diff_eq(DMat3::IDENTITY, EPS));
            assert!((det(p, s, t) - before.signum()).abs() < EPS);
        }
    }

    /// Blender's dead band: secondaries less than ~0.0057° from orthogonal (|cos| ≤ 1e-4) are left
    /// as they are (normalised if asked), so that small shear survives.
    #[test]
    fn orthogonalize_stable_dead_band() {
        let (second, third) = (DVec3::new(3.0, 0.0, 0.0), DVec3::new(5e-5, 0.0, 1.0));
        let [_, s, t] = orthogonalize_stable(DVec3::Y, second, third, false);
        assert_eq!((s, t), (second, third));
        let [_, s, t] = orthogonalize_stable(DVec3::Y, second, third, true);
        assert_eq!(s, DVec3::X);
        assert_vec_near(t, third.normalize(), "unit third");
    }
}
