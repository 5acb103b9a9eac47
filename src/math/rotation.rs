//! Rotation matrices and their quaternions, for one matrix or two side by side ([`Lanes`]).

use super::lanes::Lanes;

/// Three columns of a 3×3 matrix, each entry one value per lane.
pub(super) type Cols<L> = [[L; 3]; 3];

/// A quaternion `[x, y, z, w]`, each component one value per lane.
pub(super) type Quat<L> = [L; 4];

/// The Hamilton product `a·b`: `(a_w·b_v + b_w·a_v + a_v × b_v, a_w·b_w − a_v·b_v)`.
#[inline(always)]
pub(super) fn product<L: Lanes>(a: Quat<L>, b: Quat<L>) -> Quat<L> {
    let ([ax, ay, az, aw], [bx, by, bz, bw]) = (a, b);
    [
        aw * bx + bw * ax + (ay * bz - az * by),
        aw * by + bw * ay + (az * bx - ax * bz),
        aw * bz + bw * az + (ax * by - ay * bx),
        aw * bw - (ax * bx + ay * by + az * bz),
    ]
}

/// The rotation matrix of a unit quaternion.
#[inline(always)]
pub(super) fn matrix_of<L: Lanes>(q: Quat<L>) -> Cols<L> {
    let [x, y, z, w] = q;
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let (xy, xz, yz, wx, wy, wz) = (x * y, x * z, y * z, w * x, w * y, w * z);
    [
        [one - two * (yy + zz), two * (xy + wz), two * (xz - wy)],
        [two * (xy - wz), one - two * (xx + zz), two * (yz + wx)],
        [two * (xz + wy), two * (yz - wx), one - two * (xx + yy)],
    ]
}

/// `a·b`.
#[inline(always)]
pub(super) fn times<L: Lanes>(a: &Cols<L>, b: &Cols<L>) -> Cols<L> {
    // Column j of a·b is Σ_k a_k·b[j][k].
    std::array::from_fn(|j| std::array::from_fn(|i| a[0][i] * b[j][0] + a[1][i] * b[j][1] + a[2][i] * b[j][2]))
}

/// `a·bᵀ`.
#[inline(always)]
pub(super) fn times_transpose<L: Lanes>(a: &Cols<L>, b: &Cols<L>) -> Cols<L> {
    // Column j of a·bᵀ is Σ_k a_k·b_k[j].
    std::array::from_fn(|j| std::array::from_fn(|i| a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j]))
}

/// The unit quaternion, with `w ≥ 0`, of a rotation matrix (orthonormal up to rounding).
///
/// The textbook method (`DQuat::from_mat3`) picks, by a tree of branches, the largest of the four `4q²` values
/// on the diagonal combinations and divides the other products by it; for arbitrary rotations those branches
/// mispredict about half the time. Here all four candidates are formed, the largest is picked by selects, and the
/// result is brought to unit length by one Newton step (the matrix is orthonormal to rounding, so the length is 1
/// up to about 1e-15 before it and to rounding after it).
#[inline(always)]
pub(super) fn quat_from_rotation<L: Lanes>(m: &Cols<L>) -> Quat<L> {
    let [[m00, m01, m02], [m10, m11, m12], [m20, m21, m22]] = *m;
    let one = L::splat(1.0);
    // Row k holds 4·q_k·(x, y, z, w); its diagonal entry is 4·q_k².
    let rows = [
        [one + m00 - m11 - m22, m01 + m10, m02 + m20, m12 - m21],
        [m01 + m10, one - m00 + m11 - m22, m12 + m21, m20 - m02],
        [m02 + m20, m12 + m21, one - m00 - m11 + m22, m01 - m10],
        [m12 - m21, m20 - m02, m01 - m10, one + m00 + m11 + m22],
    ];
    // The row with the largest diagonal entry, by selects rather than an index (which would go through memory).
    let pick = |a: Quat<L>, b: Quat<L>, b_wins: L::Mask| std::array::from_fn(|i| L::select(b_wins, b[i], a[i]));
    let [r0, r1, r2, r3] = rows;
    let (r01, d01) = (pick(r0, r1, r0[0].lt(r1[1])), r0[0].max(r1[1]));
    let (r23, d23) = (pick(r2, r3, r2[2].lt(r3[3])), r2[2].max(r3[3]));
    let row: Quat<L> = pick(r01, r23, d01.lt(d23));
    // q = row / (4·q_k) with q_k = √(4q_k²)/2, and the sign that makes w ≥ 0.
    let scale = (L::splat(0.5) / d01.max(d23).sqrt()).times_sign_of(row[3]);
    let q = row.map(|c| c * scale);
    let length_squared = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    let newton = L::splat(1.5) - L::splat(0.5) * length_squared;
    q.map(|c| c * newton)
}

#[cfg(test)]
mod tests {
    use glam::{DMat3, DQuat, DVec3};
    use rand::{RngExt, SeedableRng};
    use rand_xorshift::XorShiftRng;
    use wide::f64x2;

    use super::*;

    fn random_quat(rng: &mut XorShiftRng) -> DQuat {
        DQuat::from_array(std::array::from_fn(|_| rng.random::<f64>() - 0.5)).normalize()
    }

    fn quat_of(m: &DMat3) -> DQuat {
        DQuat::from_array(quat_from_rotation(&m.to_cols_array_2d()))
    }

    #[test]
    fn quat_from_rotation_matches_glam() {
        let mut rng = XorShiftRng::seed_from_u64(7);
        for _ in 0..1000 {
            let q = random_quat(&mut rng);
            let ours = quat_of(&DMat3::from_quat(q));
            let theirs = DQuat::from_mat3(&DMat3::from_quat(q));
            assert!(ours.w >= 0.0);
            assert!(ours.abs_diff_eq(theirs, 1e-15) || ours.abs_diff_eq(-theirs, 1e-15), "{ours} vs {theirs}");
        }
        // Half turns have w = 0: the other components decide.
        let half_turn = quat_of(&DMat3::from_diagonal(DVec3::new(1.0, -1.0, -1.0)));
        assert!(half_turn.abs_diff_eq(DQuat::from_xyzw(1.0, 0.0, 0.0, 0.0), 1e-15));
    }

    #[test]
    fn matrices_match_glam_and_lanes_match_single_values() {
        let mut rng = XorShiftRng::seed_from_u64(9);
        for _ in 0..100 {
            let (p, q) = (random_quat(&mut rng), random_quat(&mut rng));
            let [mp, mq] = [p, q].map(|x| matrix_of(x.to_array()));
            assert!(DMat3::from_cols_array_2d(&mp).abs_diff_eq(DMat3::from_quat(p), 1e-15));
            let (gp, gq) = (DMat3::from_quat(p), DMat3::from_quat(q));
            assert!(DQuat::from_array(product(p.to_array(), q.to_array())).abs_diff_eq(p * q, 1e-15));
            assert!(DMat3::from_cols_array_2d(&times(&mp, &mq)).abs_diff_eq(gp * gq, 1e-15));
            assert!(DMat3::from_cols_array_2d(&times_transpose(&mp, &mq)).abs_diff_eq(gp * gq.transpose(), 1e-15));
            // Two matrices in lanes give each one's own quaternion, bit for bit.
            let joined: Cols<f64x2> =
                std::array::from_fn(|j| std::array::from_fn(|i| f64x2::from([mp[j][i], mq[j][i]])));
            let both = quat_from_rotation(&joined);
            for (lane, m) in [mp, mq].iter().enumerate() {
                assert_eq!(both.map(|c| c.to_array()[lane]), quat_from_rotation(m));
            }
        }
    }
}
