//! The polar decomposition against independent oracles: closed forms derived by hand, recomposition of random
//! parts, and nalgebra's SVD-based polar factor.

use bonescope::math::{AffineParts, decompose, decompose_all, decompose_near, quat_angle, shear_deg};
use glam::{DMat3, DMat4, DQuat, DVec3};
use proptest::prelude::*;

/// Relative difference of two matrices in the max norm, against the larger of their sizes (or 1).
fn relative_error(a: &DMat4, b: &DMat4) -> f64 {
    let diff = (*a - *b).to_cols_array().iter().map(|x| x.abs()).fold(0.0, f64::max);
    let size = a.to_cols_array().iter().chain(b.to_cols_array().iter()).map(|x| x.abs()).fold(1e-300, f64::max);
    diff / size
}

fn assert_parts_finite(p: &AffineParts) {
    assert!(p.translation.is_finite() && p.rotation.is_finite() && p.stretch.is_finite() && p.scale.is_finite());
    assert!((p.rotation.length() - 1.0).abs() < 1e-12 && (p.stretch.length() - 1.0).abs() < 1e-12);
    assert!(p.sign == 1.0 || p.sign == -1.0);
    assert!(p.scale.min_element() >= 0.0);
}

fn rot_z_matrix(m: DMat3) -> DMat4 {
    DMat4::from_mat3(m)
}

#[test]
fn rotation_times_axis_aligned_scale() {
    let r = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
    let m = DMat4::from_scale_rotation_translation(DVec3::new(2.0, 3.0, 4.0), r, DVec3::new(1.0, -2.0, 5.0));
    let p = decompose(&m);
    assert!(p.rotation.abs_diff_eq(r, 1e-14) || p.rotation.abs_diff_eq(-r, 1e-14));
    assert_eq!(p.stretch, DQuat::IDENTITY);
    assert!(p.scale.abs_diff_eq(DVec3::new(2.0, 3.0, 4.0), 1e-13));
    assert_eq!(p.translation, DVec3::new(1.0, -2.0, 5.0));
    assert_eq!(p.sign, 1.0);
    assert!(shear_deg(&DMat3::from_mat4(m)) < 1e-12);
}

#[test]
fn mirror_goes_into_the_sign() {
    // M = R·diag(−1,1,1) = (−I)·(R·diag(1,−1,−1)): f = −1, R' = R·(180° about X), K = 1.
    let r = DQuat::from_rotation_y(0.4);
    let m = DMat4::from_quat(r) * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let p = decompose(&m);
    assert_eq!(p.sign, -1.0);
    let expected = r * DQuat::from_rotation_x(std::f64::consts::PI);
    assert!(quat_angle(p.rotation * expected.conjugate()) < 1e-12);
    assert!(p.scale.abs_diff_eq(DVec3::ONE, 1e-14));
    assert!(relative_error(&p.matrix(), &m) < 1e-14);
}

#[test]
fn planar_shear_closed_form() {
    // M = [[1,1],[0,1]] in the XY plane. By hand: MᵀM has trace 3 and det 1, so its singular values are
    // φ = (1+√5)/2 and 1/φ; Q = [[2,1],[−1,2]]/√5 (a rotation by −atan(1/2)); the eigenvector of 1/φ lies at
    // −atan(1/φ) from X, so the canonical U turns by −atan(1/φ) = −31.7175° with K = (1/φ, φ, 1). The columns
    // (1,0) and (1,1) are 45° apart: shear 45°.
    let m = rot_z_matrix(DMat3::from_cols(DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Z));
    let p = decompose(&m);
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    assert!(p.scale.abs_diff_eq(DVec3::new(1.0 / phi, phi, 1.0), 1e-14), "{:?}", p.scale);
    assert!(p.stretch.abs_diff_eq(DQuat::from_rotation_z(-(1.0 / phi).atan()), 1e-14), "{:?}", p.stretch);
    assert!(p.rotation.abs_diff_eq(DQuat::from_rotation_z(-(0.5f64).atan()), 1e-14), "{:?}", p.rotation);
    assert!((p.stretch_angle_deg() - 31.717474411461005).abs() < 1e-10);
    assert!((shear_deg(&DMat3::from_mat4(m)) - 45.0).abs() < 1e-12);
    assert!(relative_error(&p.matrix(), &m) < 1e-15);
}

#[test]
fn two_equal_factors_turn_the_distinct_axis_onto_the_nearest_local_axis() {
    // S = U·diag(3,1,1)·Uᵀ with U = 20° about Z: only the stretched direction (cos 20°, sin 20°, 0) matters;
    // the canonical U is the 20° turn, and a 30° twist about the stretched axis changes nothing.
    let u = DQuat::from_rotation_z(20f64.to_radians()) * DQuat::from_rotation_x(30f64.to_radians());
    let parts = AffineParts {
        translation: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
        stretch: u,
        scale: DVec3::new(3.0, 1.0, 1.0),
        sign: 1.0,
    };
    let p = decompose(&parts.matrix());
    assert!(p.stretch.abs_diff_eq(DQuat::from_rotation_z(20f64.to_radians()), 1e-13), "{:?}", p.stretch);
    assert!(p.scale.abs_diff_eq(DVec3::new(3.0, 1.0, 1.0), 1e-13));
}

#[test]
fn uniform_scale_reports_identity_stretch_despite_rounding() {
    // A long product of rotations and a uniform scale carries rounding noise in every entry.
    let mut m = DMat4::from_scale(DVec3::splat(1.7));
    for i in 0..50 {
        m *= DMat4::from_quat(DQuat::from_euler(glam::EulerRot::ZXY, 0.1 * i as f64, 0.37, -0.2));
    }
    let p = decompose(&m);
    assert_eq!(p.stretch, DQuat::IDENTITY);
    assert!(p.scale.abs_diff_eq(DVec3::splat(1.7), 1e-12));
    // Two nearly equal factors (difference 1e-13) with a third distinct: the stretch stays the identity too.
    let r = DMat4::from_quat(DQuat::from_rotation_x(0.3) * DQuat::from_rotation_y(1.2));
    let m = r * DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0 + 1e-13));
    assert_eq!(decompose(&m).stretch_angle_deg(), 0.0);
}

#[test]
fn extreme_scales_from_1e_minus_6_to_1e6() {
    let r = DQuat::from_euler(glam::EulerRot::XYZ, 0.5, 0.25, -0.75);
    for scale in [DVec3::new(1e-6, 1.0, 1e6), DVec3::new(1e6, 1e6, 1e-6), DVec3::splat(1e-6), DVec3::splat(1e6)] {
        for stretch in [DQuat::IDENTITY, DQuat::from_euler(glam::EulerRot::YXZ, 0.2, 0.4, 0.1)] {
            let parts = AffineParts { translation: DVec3::new(3.0, 2.0, 1.0), rotation: r, stretch, scale, sign: 1.0 };
            let m = parts.matrix();
            let p = decompose(&m);
            assert_parts_finite(&p);
            assert!(relative_error(&p.matrix(), &m) < 1e-9, "scale {scale}: {}", relative_error(&p.matrix(), &m));
        }
    }
}

#[test]
fn degenerate_matrices_give_finite_parts() {
    let r = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.5, 0.25, -0.75));
    let cases = [
        DMat3::ZERO,
        r * DMat3::from_diagonal(DVec3::new(1.0, 0.0, 0.0)),
        r * DMat3::from_diagonal(DVec3::new(2.0, 3.0, 0.0)),
        // Rank 2 with shear: the third column is the sum of the first two.
        DMat3::from_cols(DVec3::new(1.0, 2.0, 0.5), DVec3::new(-1.0, 0.5, 2.0), DVec3::new(0.0, 2.5, 2.5)),
        DMat3::from_cols(DVec3::ONE, DVec3::ONE, DVec3::ONE),
        DMat3::from_cols(DVec3::X, DVec3::X * 1e-300, DVec3::Z),
    ];
    for a in cases {
        let m = DMat4::from_mat3(a);
        let p = decompose(&m);
        assert_parts_finite(&p);
        // A polar decomposition exists for singular matrices too, so recomposition stays exact.
        assert!(relative_error(&p.matrix(), &m) < 1e-12, "{a}: {}", relative_error(&p.matrix(), &m));
        assert!(p.scale.min_element() < 1e-12 * p.scale.max_element().max(1e-300) || a == DMat3::ZERO);
    }
    let nan = DMat4::from_cols_array(&[f64::NAN; 16]);
    let p = decompose(&nan);
    assert!(p.rotation.is_finite() && p.stretch.is_finite() && p.scale == DVec3::ZERO);
    let inf = DMat4::from_scale(DVec3::new(f64::INFINITY, 1.0, 1.0));
    assert!(decompose(&inf).scale.is_finite());
}

fn unit_quat() -> impl Strategy<Value = DQuat> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_filter("non-zero", |(x, y, z, w)| x * x + y * y + z * z + w * w > 1e-3)
        .prop_map(|(x, y, z, w)| DQuat::from_xyzw(x, y, z, w).normalize())
}

fn log_scale() -> impl Strategy<Value = f64> + Clone {
    (-3.0..3.0f64).prop_map(|e| 10f64.powf(e))
}

fn random_parts() -> impl Strategy<Value = AffineParts> {
    parts_with_scales(log_scale())
}

fn parts_with_scales(scale: impl Strategy<Value = f64> + Clone) -> impl Strategy<Value = AffineParts> {
    (
        (-100.0..100.0f64, -100.0..100.0f64, -100.0..100.0f64),
        unit_quat(),
        unit_quat(),
        (scale.clone(), scale.clone(), scale),
        prop::bool::ANY,
    )
        .prop_map(|((tx, ty, tz), rotation, stretch, (kx, ky, kz), mirrored)| AffineParts {
            translation: DVec3::new(tx, ty, tz),
            rotation,
            stretch,
            scale: DVec3::new(kx, ky, kz),
            sign: if mirrored { -1.0 } else { 1.0 },
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn recomposition_round_trip(parts in random_parts()) {
        let m = parts.matrix();
        let p = decompose(&m);
        assert_parts_finite(&p);
        prop_assert!(relative_error(&p.matrix(), &m) <= 1e-9, "error {}", relative_error(&p.matrix(), &m));
        prop_assert_eq!(p.sign, parts.sign);
        // The factors are a permutation of the ones it was built from.
        let mut got = p.scale.to_array();
        let mut want = parts.scale.to_array();
        got.sort_by(f64::total_cmp);
        want.sort_by(f64::total_cmp);
        for (g, w) in got.iter().zip(want) {
            prop_assert!((g - w).abs() <= 1e-9 * w.max(1.0));
        }
        // The canonical U is never farther from the identity than the one the matrix was built with.
        prop_assert!(p.stretch_angle_deg() <= parts.stretch_angle_deg() + 1e-6);
    }

    #[test]
    fn axis_aligned_scale_has_identity_stretch(rotation in unit_quat(), k in (log_scale(), log_scale(), log_scale())) {
        let m = DMat4::from_scale_rotation_translation(DVec3::new(k.0, k.1, k.2), rotation, DVec3::ONE);
        let p = decompose(&m);
        prop_assert!(p.stretch_angle_deg() < 1e-6, "stretch {}", p.stretch_angle_deg());
        prop_assert!(shear_deg(&DMat3::from_mat4(m)) < 1e-9);
    }

    #[test]
    fn rotation_factor_matches_nalgebra_svd_polar(parts in parts_with_scales(0.1..10.0f64)) {
        let m = DMat3::from_mat4(parts.matrix());
        let p = decompose(&DMat4::from_mat3(m));
        let ours = DMat3::from_quat(p.rotation) * p.sign;
        let na = nalgebra::Matrix3::from_column_slice(&m.to_cols_array());
        let (_, unitary) = na.polar();
        let theirs = DMat3::from_cols_array(unitary.as_slice().try_into().unwrap());
        // The orthogonal polar factor is unique for non-singular matrices. nalgebra's 3×3 SVD goes through the
        // eigenvectors of MᵀM, so its error grows with cond(M)²·ε: the factors here stay within 0.1..10.
        prop_assert!(ours.abs_diff_eq(theirs, 1e-9), "ours {ours} theirs {theirs}");
    }

    /// A warm start only shortens the search: from any start, near the answer or far from it, the parts are those
    /// of the cold decomposition (rotation and stretch compared as rotations, to rounding).
    #[test]
    fn the_result_does_not_depend_on_where_the_search_starts(
        parts in random_parts(),
        start in unit_quat(),
        nudge in unit_quat(),
        far in any::<bool>(),
    ) {
        let m = parts.matrix();
        let cold = decompose(&m);
        // Near: the cold stretch turned by a tenth of a random rotation; far: any rotation.
        let start = if far { start } else { cold.stretch * DQuat::IDENTITY.slerp(nudge, 0.1) };
        assert_same_parts(&decompose_near(&m, start), &cold, &m);
    }

    /// Decomposing a whole pose at once gives each matrix's own decomposition, whatever the mix (sheared pairs,
    /// shortcuts in between, singular matrices, an odd one out at the end).
    #[test]
    fn decomposing_all_at_once_gives_each_decomposition(ms in prop::collection::vec(any_matrix(), 0..12)) {
        let all = decompose_all(&ms);
        prop_assert_eq!(all.len(), ms.len());
        for (got, m) in all.iter().zip(&ms) {
            assert_parts_finite(got);
            assert_same_parts(got, &decompose(m), m);
        }
    }
}

/// Sheared, shear-free, and singular (a factor of zero) matrices.
fn any_matrix() -> impl Strategy<Value = DMat4> {
    prop_oneof![
        random_parts().prop_map(|p| p.matrix()),
        random_parts().prop_map(|p| AffineParts { stretch: DQuat::IDENTITY, ..p }.matrix()),
        random_parts().prop_map(|p| AffineParts { scale: DVec3::new(p.scale.x, 0.0, p.scale.z), ..p }.matrix()),
    ]
}

/// `got` and `expected` are parts of `m` that agree to rounding: both recompose `m` with the same factors; sign,
/// rotation and stretch angle agree where they are unique (no zero factor).
fn assert_same_parts(got: &AffineParts, expected: &AffineParts, m: &DMat4) {
    assert!(relative_error(&got.matrix(), m) <= 1e-9, "{got:?} for {m}");
    let largest = expected.scale.max_element();
    assert!(got.scale.abs_diff_eq(expected.scale, 1e-9 * largest.max(1.0)), "{got:?} {expected:?}");
    if expected.scale.min_element() > 1e-9 * largest {
        assert_eq!(got.sign, expected.sign);
        assert!(quat_angle(got.rotation * expected.rotation.inverse()) < 1e-7, "{got:?} {expected:?}");
        assert!((got.stretch_angle_deg() - expected.stretch_angle_deg()).abs() < 1e-6, "{got:?} {expected:?}");
    }
}

#[test]
fn decomposing_all_keeps_the_order_and_survives_bad_matrices() {
    let sheared = AffineParts {
        translation: DVec3::new(1.0, 2.0, 3.0),
        rotation: DQuat::from_rotation_y(0.7),
        stretch: DQuat::from_rotation_z(0.4),
        scale: DVec3::new(1.0, 2.0, 3.0),
        sign: 1.0,
    }
    .matrix();
    let nan = DMat4::from_cols_array(&[f64::NAN; 16]);
    let ms = [
        sheared,
        nan,
        DMat4::from_scale(DVec3::splat(2.0)),
        DMat4::from_mat3(DMat3::ZERO),
        DMat4::from_scale(DVec3::splat(1e-7)) * sheared,
        sheared,
    ];
    let all = decompose_all(&ms);
    for (i, (got, m)) in all.iter().zip(&ms).enumerate() {
        assert!(got.rotation.is_finite() && got.scale.is_finite() && got.stretch.is_finite(), "{i}");
        if m.is_finite() {
            assert_same_parts(got, &decompose(m), m);
        }
    }
    assert_eq!(all[1].scale, DVec3::ZERO);
    assert!(decompose_all(&[]).is_empty());
}
