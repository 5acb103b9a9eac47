//! Shoemake's polar decomposition of an affine matrix, `M = T·F·R·U·K·Uᵀ` ("Polar Matrix Decomposition",
//! Graphics Gems IV, 1994), in `f64`, made robust where the original is not.
//!
//! Shoemake reaches the parts through two iterations in a row: Newton's for the polar factor `Q` of the 3×3 part
//! `A = Q·S`, then Jacobi's for the spectral decomposition of the stretch `S`. Both fall out of one singular value
//! decomposition `A = W·Σ·Vᵀ` (`svd.rs`, one-sided Jacobi), since `Q = W·Vᵀ` and `S = V·Σ·Vᵀ`. That is one
//! iteration instead of two, and more accurate: the SVD never inverts `A` the way Newton does, so the parts stay
//! exact to rounding at scale ratios of 1e6. Steps:
//! 1. `A = F·W·Σ·Vᵀ` with `W` and `V` rotations and `F = −I` when `det A < 0` (the SVD with the sign of the
//!    determinant taken out of `W`);
//! 2. `R = W·Vᵀ`, a proper rotation;
//! 3. `U = V`, `K = Σ`;
//! 4. the canonical `U`: among the frames that give the same `S` (axis permutations, and free turns in the plane
//!    of equal scale factors) the one closest to the identity. Scale factors within [`EQUAL_SCALE_TOLERANCE`] of each
//!    other count as equal, so uniformly scaled bones report `U = I` instead of a frame picked by rounding noise.
//!
//! Most matrices in an animation are plain rotation·scale with orthogonal columns; they take a shortcut: the SVD
//! does no rotation (`V = I`), and step 4 is skipped.
//!
//! Non-finite input gives the identity rotation and zero scale (never NaN, never a hang).

use glam::{DMat3, DMat4, DQuat, DVec3};

use super::rotation::quat_from_rotation;
use super::svd::{Col, Gram, Svd, svd, svd_each};
use crate::model::{Transform, affine};

/// Scale factors whose difference is at most this fraction of the largest one are treated as equal when `U` is
/// chosen. Recomposition is exact up to that difference.
pub const EQUAL_SCALE_TOLERANCE: f64 = 1e-10;

/// Columns whose cosine is at most this are orthogonal for the shortcut (about 1e-11 degrees from 90°).
const ORTHOGONAL_COSINE: f64 = 2e-13;

/// The shortcut also wants the shortest column at least this fraction of the longest: below it, a cosine of
/// 2e-13 would no longer bound the error relative to the short column.
const SHORTCUT_LENGTH_RATIO: f64 = 1e-6;

/// The parts of `M = T(translation)·(sign·I)·R(rotation)·U·diag(scale)·Uᵀ` with `U = R(stretch)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AffineParts {
    pub translation: DVec3,
    /// The essential rotation `R`.
    pub rotation: DQuat,
    /// The stretch rotation `U`: the frame in which `scale` applies. Identity unless the matrix shears.
    pub stretch: DQuat,
    /// The stretch factors `K`, all ≥ 0.
    pub scale: DVec3,
    /// `−1` when the matrix mirrors (negative determinant), else `1`.
    pub sign: f64,
}

impl AffineParts {
    /// The parts of the identity matrix.
    pub const IDENTITY: AffineParts = AffineParts {
        translation: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
        stretch: DQuat::IDENTITY,
        scale: DVec3::ONE,
        sign: 1.0,
    };

    /// The same with the scale factors over `length_scale`: a model matrix's over the unit conversion above its
    /// bone are the factors the file's author set.
    pub fn authored(self, length_scale: f64) -> Self {
        AffineParts { scale: self.scale / length_scale, ..self }
    }

    /// The matrix these parts describe.
    pub fn matrix(&self) -> DMat4 {
        affine(self.linear(), self.translation)
    }

    /// The 3×3 part `F·R·U·K·Uᵀ`.
    pub fn linear(&self) -> DMat3 {
        let u = DMat3::from_quat(self.stretch);
        let s = u * DMat3::from_diagonal(self.scale) * u.transpose();
        DMat3::from_quat(self.rotation) * s * self.sign
    }

    /// The parts as a local transform, the mirror carried in the scale's sign (`−I` commutes, so
    /// `F·R·U·K·Uᵀ = R·U·(−K)·Uᵀ`).
    pub fn transform(&self) -> Transform {
        Transform {
            translation: self.translation,
            rotation: self.rotation,
            scale: self.sign * self.scale,
            stretch: self.stretch,
        }
    }

    /// The angle of the stretch rotation `U`, in degrees (0 for a shear-free matrix).
    pub fn stretch_angle_deg(&self) -> f64 {
        quat_angle(self.stretch).to_degrees()
    }

    /// The angle of `U` once scale factors within `relative_tolerance` of each other count as equal, in degrees.
    ///
    /// Between nearly equal factors `U` may turn freely without changing the matrix by more than their difference,
    /// so this is the angle that matters when asking whether a bone is stretched. It is the angle of the frame
    /// [`decompose`] would choose with that tolerance, found without building the frame: with distinct factors the
    /// smallest angle over the 24 frames that differ by an axis permutation, with one distinct factor the angle
    /// between its axis and the nearest local axis, and 0 when all count as equal.
    pub fn stretch_angle_deg_within(&self, relative_tolerance: f64) -> f64 {
        angle_of_half_cosine(stretch_half_cosine_within(self.stretch, self.scale, relative_tolerance))
    }

    /// The stretch rotation once scale factors within `relative_tolerance` of each other count as equal: the frame
    /// whose angle is [`AffineParts::stretch_angle_deg_within`] (what plots show, beside the findings).
    pub fn stretch_within(&self, relative_tolerance: f64) -> DQuat {
        canonical_stretch(self.stretch, self.scale, relative_tolerance).0
    }

    /// How unequal the stretch factors are: `max/min − 1` (0 for uniform scale, infinite when one is 0).
    pub fn anisotropy(&self) -> f64 {
        let (min, max) = (self.scale.min_element(), self.scale.max_element());
        if max == 0.0 { 0.0 } else { max / min - 1.0 }
    }
}

/// `cos(θ/2)` of the angle `θ` of [`AffineParts::stretch_angle_deg_within`] for the frame `stretch` with factors
/// `scale`: 1 for no turn, smaller for larger turns, and without an inverse cosine (a whole-clip scan compares these
/// and converts only the worst).
#[inline]
pub fn stretch_half_cosine_within(stretch: DQuat, scale: DVec3, relative_tolerance: f64) -> f64 {
    if stretch == DQuat::IDENTITY {
        return 1.0;
    }
    // With one distinct factor the angle θ is between its axis and the nearest local one: cos θ = c, and
    // cos(θ/2) = √((1 + c)/2).
    let to_nearest_axis = |direction: DVec3| ((1.0 + direction.abs().max_element().min(1.0)) * 0.5).sqrt();
    match equal_factors(scale, relative_tolerance) {
        [false, false, false] => closest_axis_permutation_w(stretch).min(1.0),
        [true, false, false] => to_nearest_axis(stretch * DVec3::Z),
        [false, true, false] => to_nearest_axis(stretch * DVec3::Y),
        [false, false, true] => to_nearest_axis(stretch * DVec3::X),
        _ => 1.0,
    }
}

/// The angle `θ` in degrees whose `cos(θ/2)` is `half_cosine`.
pub fn angle_of_half_cosine(half_cosine: f64) -> f64 {
    (2.0 * half_cosine.min(1.0).acos()).to_degrees()
}

/// The angle between two rotations, in radians, in `[0, π]` (accurate for tiny angles too, where an inverse cosine
/// of their dot product loses half the digits). Equal quaternions are exactly 0 apart (their product's rounding
/// would say 1e-17).
pub fn angle_between(a: DQuat, b: DQuat) -> f64 {
    if a == b {
        return 0.0;
    }
    let d = a.conjugate() * b;
    2.0 * d.xyz().length().atan2(d.w.abs())
}

/// The angle of a unit quaternion's rotation, in radians, in `[0, π]`.
pub fn quat_angle(q: DQuat) -> f64 {
    2.0 * q.w.abs().min(1.0).acos()
}

/// Decomposes an affine matrix (the bottom row is ignored).
pub fn decompose(m: &DMat4) -> AffineParts {
    decompose_near(m, DQuat::IDENTITY)
}

/// [`decompose`], searching for the stretch frame from `start`: for a sequence of similar matrices (a bone over
/// consecutive frames) the previous one's `stretch` makes the search short. The result does not depend on `start`
/// beyond rounding.
pub fn decompose_near(m: &DMat4, start: DQuat) -> AffineParts {
    parts(svd(&linear_part(m), start, shortcut), m)
}

/// [`decompose`] of every matrix, two at a time where they shear (see `lanes.rs`): the same parts up to rounding,
/// in less time per matrix than one call each (the whole skeleton of a pose, every bone at once).
pub fn decompose_all(ms: &[DMat4]) -> Vec<AffineParts> {
    let mut all = vec![AffineParts::IDENTITY; ms.len()];
    svd_each(ms.iter().map(linear_part), shortcut, |i, svd| all[i] = parts(svd, &ms[i]));
    all
}

/// The 3×3 part of `m` as columns, or the zero matrix when it is not finite (so that non-finite input decomposes
/// into the identity rotation and zero scale, never NaN).
fn linear_part(m: &DMat4) -> [Col; 3] {
    let a = DMat3::from_mat4(*m);
    if a.is_finite() { a.to_cols_array_2d() } else { [[0.0; 3]; 3] }
}

/// `m`'s parts from the SVD of its 3×3 part.
fn parts(svd: Svd, m: &DMat4) -> AffineParts {
    let (translation, rotation, sign) = (m.w_axis.truncate(), svd.rotation, svd.sign);
    let scale = DVec3::from_array(svd.sigma);
    if svd.v == DQuat::IDENTITY {
        // The columns were orthogonal: M = T·F·R·K with U = I.
        return AffineParts { translation, rotation, stretch: DQuat::IDENTITY, scale, sign };
    }
    let (stretch, scale) = canonical_stretch(svd.v, scale, EQUAL_SCALE_TOLERANCE);
    AffineParts { translation, rotation, stretch, scale, sign }
}

/// The parts of `m` when its stretch is already known, `M = F·R·V·K·Vᵀ` with `V = R(stretch)` in any frame (a
/// whole-clip analysis passes stretches down the hierarchy): `R = F·M·V·K⁻¹·Vᵀ` without an SVD, then the canonical
/// frame as [`decompose`] chooses it. `None` when `K` is too unequal for dividing it out to keep the accuracy of
/// [`decompose`] (a factor below 1e-3 of the largest: the rotation's error grows with the ratio's inverse, to
/// about 1e-13 there), or not finite.
pub fn decompose_with_stretch(m: &DMat4, stretch: DQuat, scale: DVec3, sign: f64) -> Option<AffineParts> {
    let (min, max) = (scale.min_element(), scale.max_element());
    if !(min >= STRETCH_RATIO * max && max.is_finite() && min > 0.0) {
        return None;
    }
    let v = DMat3::from_quat(stretch);
    let inverse_stretch = v * DMat3::from_diagonal(scale.recip()) * v.transpose();
    let rotation = quat_of(&(DMat3::from_mat4(*m) * inverse_stretch * sign));
    let (stretch, scale) = if stretch == DQuat::IDENTITY {
        (stretch, scale)
    } else {
        canonical_stretch(stretch, scale, EQUAL_SCALE_TOLERANCE)
    };
    Some(AffineParts { translation: m.w_axis.truncate(), rotation, stretch, scale, sign })
}

/// The smallest ratio of stretch factors [`decompose_with_stretch`] divides out.
const STRETCH_RATIO: f64 = 1e-3;

/// Whether the columns are non-zero, of comparable lengths, and orthogonal to within [`ORTHOGONAL_COSINE`]: then
/// `U = I` and `K` is the column lengths, with no rotation to search for.
fn shortcut(gram: &Gram) -> bool {
    let [x, y, z] = gram.lengths_squared;
    let (shortest, longest) = (x.min(y).min(z), x.max(y).max(z));
    let orthogonal = |dot: f64, a: f64, b: f64| dot * dot <= ORTHOGONAL_COSINE * ORTHOGONAL_COSINE * a * b;
    let [xy, xz, yz] = gram.dots;
    shortest > 0.0
        && shortest >= longest * (SHORTCUT_LENGTH_RATIO * SHORTCUT_LENGTH_RATIO)
        && orthogonal(xy, x, y)
        && orthogonal(xz, x, z)
        && orthogonal(yz, y, z)
}

/// Among the frames that give the same `U·K·Uᵀ` as `stretch` with factors `scale` (axis permutations, and free
/// turns between factors within [`EQUAL_SCALE_TOLERANCE`] of each other), the one closest to `reference`, with the
/// factors permuted to match. Choosing each time's frame nearest the previous one gives a stretch rotation that
/// moves continuously over time instead of jumping between equivalent frames.
pub fn stretch_nearest(stretch: DQuat, scale: DVec3, reference: DQuat) -> (DQuat, DVec3) {
    let (relative, scale) = canonical_stretch(reference.conjugate() * stretch, scale, EQUAL_SCALE_TOLERANCE);
    ((reference * relative).normalize(), scale)
}

/// The stretch frame closest to the identity that gives the same `U·K·Uᵀ`, with `K` permuted to match; factors
/// within `relative_tolerance` of the largest count as equal.
fn canonical_stretch(u: DQuat, k: DVec3, relative_tolerance: f64) -> (DQuat, DVec3) {
    let distinct = match equal_factors(k, relative_tolerance) {
        [false, false, false] => return closest_axis_permutation(u, k),
        [true, false, false] => 2,
        [false, true, false] => 1,
        [false, false, true] => 0,
        _ => return (DQuat::IDENTITY, k),
    };
    // Two equal factors: only the direction of the distinct one matters. Put it on the local axis nearest to it by
    // the shortest arc, which is the smallest rotation that does so.
    let direction = u * DVec3::AXES[distinct];
    let axis = direction.abs().max_position();
    let target = direction * direction[axis].signum();
    let stretch = DQuat::from_rotation_arc(DVec3::AXES[axis], target);
    let mut scale = k.to_array();
    scale.swap(axis, distinct);
    (stretch, DVec3::from_array(scale))
}

/// `|w|` of `u·p` for the axis permutation `p` that makes it largest (see [`closest_axis_permutation`]).
fn closest_axis_permutation_w(u: DQuat) -> f64 {
    let [x, y, z, w] = [u.x.abs(), u.y.abs(), u.z.abs(), u.w.abs()];
    let (high_xy, low_xy, high_zw, low_zw) = (x.max(y), x.min(y), z.max(w), z.min(w));
    let largest = high_xy.max(high_zw);
    let second = high_xy.min(high_zw).max(low_xy.max(low_zw));
    largest.max((largest + second) * std::f64::consts::FRAC_1_SQRT_2).max((x + y + z + w) * 0.5)
}

/// Which pairs of factors, (0, 1), (0, 2) and (1, 2), are within `relative_tolerance` of the largest of each other.
fn equal_factors(k: DVec3, relative_tolerance: f64) -> [bool; 3] {
    let tolerance = relative_tolerance * k.max_element();
    [(k.x - k.y).abs() <= tolerance, (k.x - k.z).abs() <= tolerance, (k.y - k.z).abs() <= tolerance]
}

/// Among the 24 rotations that permute the axes, the `p` for which `u·p` is nearest the identity (largest `|w|`);
/// returns `u·p` and `k` permuted so that `(u·p)·K'·(u·p)ᵀ = u·K·uᵀ`.
fn closest_axis_permutation(u: DQuat, k: DVec3) -> (DQuat, DVec3) {
    // w(u·p) = ⟨u, p̄⟩ with p̄ = conj(p). Over the 24 cube rotations the best |w| is one of: the largest |component|
    // of u, the two largest added and divided by √2, or all four added and halved (signs matched to u's).
    let comps = [u.x, u.y, u.z, u.w];
    let abs: [f64; 4] = std::array::from_fn(|i| comps[i].abs());
    let by_size = two_largest(abs);
    let one = abs[by_size[0]];
    let two = (abs[by_size[0]] + abs[by_size[1]]) * std::f64::consts::FRAC_1_SQRT_2;
    let all = abs.iter().sum::<f64>() * 0.5;
    let [first, second] = by_size;
    let (use_all, use_two) = (all > two && all > one, two > one);
    let bar: [f64; 4] = std::array::from_fn(|i| {
        let magnitude = if use_all {
            0.5
        } else if use_two {
            if i == first || i == second { std::f64::consts::FRAC_1_SQRT_2 } else { 0.0 }
        } else if i == first {
            1.0
        } else {
            0.0
        };
        magnitude.copysign(comps[i])
    });
    let p = DQuat::from_xyzw(-bar[0], -bar[1], -bar[2], bar[3]);
    // Both factors are unit quaternions, so the product is one up to rounding.
    let stretch = u * p;
    let stretch = if stretch.w < 0.0 { -stretch } else { stretch };
    // Column i of p is ±e_j: the new axis i carries the old factor j. Its entries are 0 or ±1 up to rounding.
    let pm = DMat3::from_quat(p);
    let carried = |column: DVec3| {
        let pick = |entry: f64, factor: f64| if entry.abs() > 0.5 { factor } else { 0.0 };
        pick(column.x, k.x) + pick(column.y, k.y) + pick(column.z, k.z)
    };
    (stretch, DVec3::new(carried(pm.x_axis), carried(pm.y_axis), carried(pm.z_axis)))
}

/// The indices of the largest and the second largest element (the earlier one first among equals).
fn two_largest(a: [f64; 4]) -> [usize; 2] {
    // (larger, smaller) of a pair, the earlier index winning ties; then the winners against each other.
    let pair = |i: usize, j: usize| if a[j] > a[i] { (j, i) } else { (i, j) };
    let ((high01, low01), (high23, low23)) = (pair(0, 1), pair(2, 3));
    if a[high23] > a[high01] {
        [high23, if a[low23] > a[high01] { low23 } else { high01 }]
    } else {
        [high01, if a[high23] > a[low01] { high23 } else { low01 }]
    }
}

/// The unit quaternion, with `w ≥ 0`, of a rotation matrix (orthonormal up to rounding).
fn quat_of(m: &DMat3) -> DQuat {
    DQuat::from_array(quat_from_rotation(&m.to_cols_array_2d()))
}

/// The largest deviation from 90°, in degrees, between any two columns of the 3×3 part: 0 for any rotation·scale
/// matrix, whatever its frame. Pairs with a zero column do not count.
pub fn shear_deg(m: &DMat3) -> f64 {
    shear_deg_of_cosine(largest_column_cosine(m))
}

/// The largest `|cos|` of the angle between two columns (pairs with a zero column do not count): the shear
/// without its inverse sine, which orders matrices the same way.
pub fn largest_column_cosine(m: &DMat3) -> f64 {
    let cols = [m.x_axis, m.y_axis, m.z_axis];
    let lengths = [cols[0].length(), cols[1].length(), cols[2].length()];
    let mut worst: f64 = 0.0;
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let product = lengths[i] * lengths[j];
        if product > 0.0 && product.is_finite() {
            worst = worst.max((cols[i].dot(cols[j]) / product).abs());
        }
    }
    worst.min(1.0)
}

/// The shear in degrees from [`largest_column_cosine`]: `|acos(c) − 90°| = asin(|c|)`.
pub fn shear_deg_of_cosine(cosine: f64) -> f64 {
    cosine.asin().to_degrees()
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_xorshift::XorShiftRng;

    use super::*;

    #[test]
    fn angles_between_rotations_are_exact_for_small_large_and_no_angles() {
        let a = DQuat::from_rotation_y(0.3);
        assert!((angle_between(a, DQuat::from_rotation_y(0.3 + 1e-9)) - 1e-9).abs() < 1e-15);
        assert!((angle_between(a, -DQuat::from_rotation_y(1.3)) - 1.0).abs() < 1e-14);
        let turned =
            DQuat::from_xyzw(0.7018638453962487, 0.7018638453962488, -0.08594848762829187, 0.08594848762829192);
        assert_eq!(angle_between(turned, turned), 0.0, "the product's rounding is no angle");
    }

    /// A rotation drawn from deterministic noise.
    fn random_quat(rng: &mut XorShiftRng) -> DQuat {
        DQuat::from_array(std::array::from_fn(|_| rng.random::<f64>() - 0.5)).normalize()
    }

    /// Given the stretch (in the SVD's frame or any equivalent one), the parts are [`decompose`]'s.
    #[test]
    fn decomposing_with_a_known_stretch_gives_the_decomposition() {
        let mut rng = XorShiftRng::seed_from_u64(5);
        let factor = |rng: &mut XorShiftRng| 0.2 + 3.0 * rng.random::<f64>();
        for case in 0..2000 {
            let (r, u) = (random_quat(&mut rng), random_quat(&mut rng));
            let k = DVec3::new(factor(&mut rng), factor(&mut rng), if case % 4 == 0 { 1.0 } else { factor(&mut rng) });
            let k = if case % 8 == 0 { DVec3::new(k.x, k.x, k.z) } else { k };
            let sign = if case % 3 == 0 { -1.0 } else { 1.0 };
            let parts = AffineParts { translation: DVec3::new(1.0, 2.0, 3.0), rotation: r, stretch: u, scale: k, sign };
            let m = parts.matrix();
            let expected = decompose(&m);
            // The frame as given and turned by a quarter turn about Z with two factors swapped: the same stretch.
            let quarter = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
            for (frame, factors) in [(u, k), (u * quarter, DVec3::new(k.y, k.x, k.z))] {
                let got = decompose_with_stretch(&m, frame, factors, sign).expect("well conditioned");
                let same_rotation = got.rotation.abs_diff_eq(expected.rotation, 1e-12)
                    || got.rotation.abs_diff_eq(-expected.rotation, 1e-12);
                assert!(same_rotation, "{case}: {:?} vs {:?}", got.rotation, expected.rotation);
                assert!(got.matrix().abs_diff_eq(m, 1e-12), "{case}");
                assert!(got.scale.abs_diff_eq(expected.scale, 1e-12), "{case}: {} vs {}", got.scale, expected.scale);
                assert!((got.stretch_angle_deg() - expected.stretch_angle_deg()).abs() < 1e-6, "{case}");
                assert_eq!(got.sign, expected.sign);
            }
        }
        let flat = DMat4::from_scale(DVec3::new(1.0, 1e-4, 1.0));
        assert_eq!(decompose_with_stretch(&flat, DQuat::IDENTITY, DVec3::new(1.0, 1e-4, 1.0), 1.0), None);
    }

    /// The nearest equivalent frame keeps the stretch and lies within the symmetry's reach of the reference.
    #[test]
    fn the_nearest_stretch_frame_follows_the_reference() {
        let mut rng = XorShiftRng::seed_from_u64(17);
        let stretch_of = |u: DQuat, k: DVec3| {
            let m = DMat3::from_quat(u);
            m * DMat3::from_diagonal(k) * m.transpose()
        };
        for case in 0..500 {
            let (u, reference) = (random_quat(&mut rng), random_quat(&mut rng));
            let k = match case % 3 {
                0 => DVec3::new(1.0, 2.0, 3.0),
                1 => DVec3::new(2.0, 1.0, 2.0),
                _ => DVec3::splat(1.5),
            };
            let (near, scale) = stretch_nearest(u, k, reference);
            assert!(stretch_of(near, scale).abs_diff_eq(stretch_of(u, k), 1e-12), "{case}: the same U·K·Uᵀ");
            // No axis permutation of the result is closer to the reference.
            let w = (reference.conjugate() * near).w.abs();
            assert!(w >= closest_axis_permutation_w(reference.conjugate() * near) - 1e-12, "{case}");
        }
        // A frame one permutation away from the reference comes back to it exactly.
        let reference = DQuat::from_rotation_y(0.4);
        let permuted = reference * DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let (near, scale) = stretch_nearest(permuted, DVec3::new(1.0, 2.0, 3.0), reference);
        assert!(near.abs_diff_eq(reference, 1e-12) || near.abs_diff_eq(-reference, 1e-12));
        assert!(scale.abs_diff_eq(DVec3::new(2.0, 1.0, 3.0), 1e-12));
    }

    /// `stretch_angle_deg_within` gives the angle of the frame `canonical_stretch` would choose.
    #[test]
    fn stretch_angle_within_matches_the_canonical_frame() {
        let mut rng = XorShiftRng::seed_from_u64(11);
        let factor_sets = [
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(2.0, 1.0, 1.0 + 1e-6),
            DVec3::new(1.0 + 1e-6, 3.0, 1.0),
            DVec3::new(0.5, 0.5 + 1e-7, 0.5),
            DVec3::new(1.0, 1.0, 1.0 + 1e-5),
        ];
        for _ in 0..200 {
            for scale in factor_sets {
                let parts = AffineParts {
                    translation: DVec3::ZERO,
                    rotation: random_quat(&mut rng),
                    stretch: random_quat(&mut rng),
                    scale,
                    sign: 1.0,
                };
                let canonical = canonical_stretch(parts.stretch, scale, 1e-4).0;
                let expected = quat_angle(canonical).to_degrees();
                let got = parts.stretch_angle_deg_within(1e-4);
                assert!((got - expected).abs() < 1e-6, "{scale}: {got} vs {expected}");
            }
        }
    }

    #[test]
    fn shear_is_the_largest_deviation_of_any_column_pair() {
        let mut rng = XorShiftRng::seed_from_u64(3);
        for _ in 0..200 {
            let m = DMat3::from_cols_array(&std::array::from_fn(|_| rng.random::<f64>() * 2.0 - 1.0));
            let cols = [m.x_axis, m.y_axis, m.z_axis];
            let expected = [(0, 1), (0, 2), (1, 2)]
                .map(|(i, j)| {
                    let cos = cols[i].dot(cols[j]) / (cols[i].length() * cols[j].length());
                    (cos.clamp(-1.0, 1.0).acos().to_degrees() - 90.0).abs()
                })
                .into_iter()
                .fold(0.0, f64::max);
            assert!((shear_deg(&m) - expected).abs() < 1e-9, "{m}");
        }
        assert_eq!(shear_deg(&DMat3::from_cols(DVec3::X, DVec3::ZERO, DVec3::Y)), 0.0);
    }
}
