//! Shoemake's polar decomposition of an affine matrix, `M = T·F·R·U·K·Uᵀ` ("Polar Matrix Decomposition",
//! Graphics Gems IV, 1994), in `f64`, made robust where the original is not.
//!
//! Steps, each a function below:
//! 1. the polar factor `Q` of the 3×3 part by Higham's scaled Newton iteration (quadratically convergent, with an
//!    iteration cap); rank-deficient or non-converging matrices fall back to an eigen-decomposition of `MᵀM`;
//! 2. `F = −I` when `det M < 0`, so `R = F·Q` is a proper rotation and `S = Qᵀ·M` is symmetric positive semi-definite;
//! 3. `S = U·K·Uᵀ` by cyclic Jacobi;
//! 4. the canonical `U`: among the frames that give the same `S` (axis permutations, and free turns in the plane
//!    of equal scale factors) the one closest to the identity. Scale factors within [`EQUAL_SCALE_TOLERANCE`] of each
//!    other count as equal, so uniformly scaled bones report `U = I` instead of a frame picked by rounding noise.
//!
//! Most matrices in an animation are plain rotation·scale with orthogonal columns; they take a shortcut that skips
//! all of the above and gives the same parts.
//!
//! Non-finite input gives the identity rotation and zero scale (never NaN, never a hang).

use glam::{DMat3, DMat4, DQuat, DVec3};

use crate::model::affine;

/// Scale factors whose difference is at most this fraction of the largest one are treated as equal when `U` is
/// chosen. Recomposition is exact up to that difference.
pub const EQUAL_SCALE_TOLERANCE: f64 = 1e-10;

/// Columns whose cosine is at most this are orthogonal for the shortcut (about 1e-11 degrees from 90°).
const ORTHOGONAL_COSINE: f64 = 2e-13;

/// Newton stops once an update changes the iterate by less than this fraction (the next one is then exact to
/// rounding, since convergence is quadratic).
const NEWTON_TOLERANCE: f64 = 1e-9;
const NEWTON_MAX_ITERATIONS: usize = 64;
const JACOBI_MAX_SWEEPS: usize = 32;

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

    /// The angle of the stretch rotation `U`, in degrees (0 for a shear-free matrix).
    pub fn stretch_angle_deg(&self) -> f64 {
        quat_angle(self.stretch).to_degrees()
    }

    /// The angle of `U` once scale factors within `relative_tolerance` of each other count as equal, in degrees.
    ///
    /// Between nearly equal factors `U` may turn freely without changing the matrix by more than their difference,
    /// so this is the angle that matters when asking whether a bone is stretched.
    pub fn stretch_angle_deg_within(&self, relative_tolerance: f64) -> f64 {
        quat_angle(canonical_stretch(self.stretch, self.scale, relative_tolerance).0).to_degrees()
    }

    /// How unequal the stretch factors are: `max/min − 1` (0 for uniform scale, infinite when one is 0).
    pub fn anisotropy(&self) -> f64 {
        let (min, max) = (self.scale.min_element(), self.scale.max_element());
        if max == 0.0 { 0.0 } else { max / min - 1.0 }
    }
}

/// The angle of a unit quaternion's rotation, in radians, in `[0, π]`.
pub fn quat_angle(q: DQuat) -> f64 {
    2.0 * q.w.abs().min(1.0).acos()
}

/// Decomposes an affine matrix (the bottom row is ignored).
pub fn decompose(m: &DMat4) -> AffineParts {
    let translation = m.w_axis.truncate();
    let a = DMat3::from_mat4(*m);
    if !a.is_finite() {
        return AffineParts {
            translation,
            rotation: DQuat::IDENTITY,
            stretch: DQuat::IDENTITY,
            scale: DVec3::ZERO,
            sign: 1.0,
        };
    }
    let (rotation, stretch, scale, sign) = orthogonal_shortcut(&a).unwrap_or_else(|| general(&a));
    AffineParts { translation, rotation, stretch, scale, sign }
}

type Parts3 = (DQuat, DQuat, DVec3, f64);

/// The parts of a matrix whose columns are non-zero and mutually orthogonal: `U = I`, `K` = column lengths.
fn orthogonal_shortcut(a: &DMat3) -> Option<Parts3> {
    let (x, y, z) = (a.x_axis, a.y_axis, a.z_axis);
    let lengths = DVec3::new(x.length(), y.length(), z.length());
    let min_length = lengths.min_element();
    if min_length <= 0.0 || min_length < lengths.max_element() * 1e-6 {
        return None;
    }
    let orthogonal = |a: DVec3, b: DVec3, la: f64, lb: f64| a.dot(b).abs() <= ORTHOGONAL_COSINE * la * lb;
    if !(orthogonal(x, y, lengths.x, lengths.y)
        && orthogonal(y, z, lengths.y, lengths.z)
        && orthogonal(x, z, lengths.x, lengths.z))
    {
        return None;
    }
    let sign = if a.determinant() < 0.0 { -1.0 } else { 1.0 };
    let q = DMat3::from_cols(x / lengths.x, y / lengths.y, z / lengths.z) * sign;
    Some((rotation_from_orthonormal(&q), DQuat::IDENTITY, lengths, sign))
}

/// The full decomposition: polar factor, sign, spectral decomposition, canonical stretch frame.
fn general(a: &DMat3) -> Parts3 {
    let (mut q, s) = polar_newton(a).unwrap_or_else(|| polar_degenerate(a));
    let sign = if q.determinant() < 0.0 { -1.0 } else { 1.0 };
    q *= sign;
    let (u, k) = symmetric_eigen(&s);
    let (stretch, scale) = canonical_stretch(rotation_from_orthonormal(&u), k.max(DVec3::ZERO), EQUAL_SCALE_TOLERANCE);
    (rotation_from_orthonormal(&q), stretch, scale, sign)
}

/// `M = Q·S` by Higham's scaled Newton iteration `X ← ½(γX + γ⁻¹X⁻ᵀ)` with the (1,∞)-norm scaling.
/// `None` when the matrix is (numerically) singular or the iteration does not settle.
fn polar_newton(a: &DMat3) -> Option<(DMat3, DMat3)> {
    let mut x = *a;
    for _ in 0..NEWTON_MAX_ITERATIONS {
        let cof = cofactor(&x);
        let det = x.x_axis.dot(cof.x_axis);
        if !det.is_finite() || det.abs() <= f64::MIN_POSITIVE * norm_frobenius(&x).powi(3).max(1.0) {
            return None;
        }
        let ratio = (norm_one(&cof) * norm_inf(&cof)) / (norm_one(&x) * norm_inf(&x));
        let gamma = (ratio.sqrt() / det.abs()).sqrt();
        let next = x * (0.5 * gamma) + cof * (0.5 / (gamma * det));
        let change = norm_one(&(next - x));
        x = next;
        if !x.is_finite() {
            return None;
        }
        if change <= NEWTON_TOLERANCE * norm_one(&x) {
            // One more step: the error is now about the square of `change`, i.e. at rounding level.
            let cof = cofactor(&x);
            let det = x.x_axis.dot(cof.x_axis);
            x = (x + cof * (1.0 / det)) * 0.5;
            return Some((x, symmetric_part(&(x.transpose() * *a))));
        }
    }
    None
}

/// The polar decomposition of a rank-deficient matrix through the eigen-decomposition `MᵀM = V·Λ·Vᵀ`:
/// `Q = W·Vᵀ` with `W`'s columns `M·vᵢ/σᵢ` where `σᵢ > 0`, completed to a proper rotation.
fn polar_degenerate(a: &DMat3) -> (DMat3, DMat3) {
    let (v, lambda) = symmetric_eigen(&(a.transpose() * *a));
    let sigma = lambda.max(DVec3::ZERO).to_array().map(f64::sqrt);
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| sigma[j].total_cmp(&sigma[i]));
    let significant = sigma[order[0]] * 1e-12;
    let mut w = [DVec3::ZERO; 3];
    for (rank, &i) in order.iter().enumerate() {
        let image = if sigma[i] > significant { *a * v.col(i) } else { DVec3::ZERO };
        w[i] = orthonormal_completion(image, &order[..rank].iter().map(|&j| w[j]).collect::<Vec<_>>());
    }
    let mut w = DMat3::from_cols(w[0], w[1], w[2]);
    if w.determinant() < 0.0 {
        // The weakest direction is free (its σ is zero unless the matrix has full rank); flip it.
        let weakest = order[2];
        *w.col_mut(weakest) = -w.col(weakest);
    }
    let q = w * v.transpose();
    (q, symmetric_part(&(q.transpose() * *a)))
}

/// `candidate` made orthogonal to the orthonormal `basis` and normalised; any unit vector orthogonal to it when
/// nothing of `candidate` is left.
fn orthonormal_completion(candidate: DVec3, basis: &[DVec3]) -> DVec3 {
    let rest = basis.iter().fold(candidate, |c, b| c - *b * b.dot(c));
    if rest.length() > 1e-9 * candidate.length().max(f64::MIN_POSITIVE) && rest.length() > 0.0 {
        return rest.normalize();
    }
    match basis {
        [] => DVec3::X,
        [b] => b.any_orthonormal_vector(),
        [b, c, ..] => b.cross(*c).normalize(),
    }
}

/// `S = U·diag(k)·Uᵀ` for symmetric `S` by cyclic Jacobi rotations; `U` is a proper rotation.
fn symmetric_eigen(s: &DMat3) -> (DMat3, DVec3) {
    let mut m = s.to_cols_array_2d();
    let mut u = DMat3::IDENTITY.to_cols_array_2d();
    let scale = m.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max);
    for _ in 0..JACOBI_MAX_SWEEPS {
        let off = m[0][1].abs() + m[0][2].abs() + m[1][2].abs();
        if off <= scale * 1e-17 || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            jacobi_rotate(&mut m, &mut u, p, q);
        }
    }
    (DMat3::from_cols_array_2d(&u), DVec3::new(m[0][0], m[1][1], m[2][2]))
}

/// One Jacobi rotation in the (p, q) plane zeroing `m[p][q]` (Golub & Van Loan, symmetric Schur).
fn jacobi_rotate(m: &mut [[f64; 3]; 3], u: &mut [[f64; 3]; 3], p: usize, q: usize) {
    let apq = m[p][q];
    if apq == 0.0 {
        return;
    }
    let theta = (m[q][q] - m[p][p]) / (2.0 * apq);
    // Infinite θ (a negligible m[p][q]) gives t = 0: no rotation.
    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    // m ← Jᵀ·m·J with J the rotation by (c, s) in the (p, q) plane; u ← u·J. Arrays are [column][row].
    for column in m.iter_mut() {
        let (row_p, row_q) = (column[p], column[q]);
        column[p] = c * row_p - s * row_q;
        column[q] = s * row_p + c * row_q;
    }
    turn_columns(m, p, q, c, s);
    m[p][q] = 0.0;
    m[q][p] = 0.0;
    turn_columns(u, p, q, c, s);
}

/// Columns p and q of `m` (stored [column][row]) turned by the plane rotation (c, s): `m ← m·J`.
fn turn_columns(m: &mut [[f64; 3]; 3], p: usize, q: usize, c: f64, s: f64) {
    let (column_p, column_q) = (m[p], m[q]);
    m[p] = std::array::from_fn(|k| c * column_p[k] - s * column_q[k]);
    m[q] = std::array::from_fn(|k| s * column_p[k] + c * column_q[k]);
}

/// The stretch frame closest to the identity that gives the same `U·K·Uᵀ`, with `K` permuted to match; factors
/// within `relative_tolerance` of the largest count as equal.
fn canonical_stretch(u: DQuat, k: DVec3, relative_tolerance: f64) -> (DQuat, DVec3) {
    let tolerance = relative_tolerance * k.max_element();
    let equal = |i: usize, j: usize| (k[i] - k[j]).abs() <= tolerance;
    let distinct = match (equal(0, 1), equal(0, 2), equal(1, 2)) {
        (false, false, false) => return closest_axis_permutation(u, k),
        (true, false, false) => 2,
        (false, true, false) => 1,
        (false, false, true) => 0,
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

/// Among the 24 rotations that permute the axes, the `p` for which `u·p` is nearest the identity (largest `|w|`);
/// returns `u·p` and `k` permuted so that `(u·p)·K'·(u·p)ᵀ = u·K·uᵀ`.
fn closest_axis_permutation(u: DQuat, k: DVec3) -> (DQuat, DVec3) {
    // w(u·p) = ⟨u, p̄⟩ with p̄ = conj(p). Over the 24 cube rotations the best |w| is one of: the largest |component|
    // of u, the two largest added and divided by √2, or all four added and halved (signs matched to u's).
    let comps = [u.x, u.y, u.z, u.w];
    let abs = comps.map(f64::abs);
    let mut by_size = [0, 1, 2, 3];
    by_size.sort_by(|&i, &j| abs[j].total_cmp(&abs[i]));
    let one = abs[by_size[0]];
    let two = (abs[by_size[0]] + abs[by_size[1]]) * std::f64::consts::FRAC_1_SQRT_2;
    let all = abs.iter().sum::<f64>() * 0.5;
    let signed = |i: usize, magnitude: f64| magnitude.copysign(comps[i]);
    let mut bar = [0.0; 4];
    if all > two && all > one {
        bar = [0, 1, 2, 3].map(|i| signed(i, 0.5));
    } else if two > one {
        for &i in &by_size[..2] {
            bar[i] = signed(i, std::f64::consts::FRAC_1_SQRT_2);
        }
    } else {
        bar[by_size[0]] = signed(by_size[0], 1.0);
    }
    let p = DQuat::from_xyzw(-bar[0], -bar[1], -bar[2], bar[3]);
    let mut stretch = (u * p).normalize();
    if stretch.w < 0.0 {
        stretch = -stretch;
    }
    // Column i of p is ±e_j: the new axis i carries the old factor j.
    let pm = DMat3::from_quat(p);
    let scale = DVec3::from_array([0, 1, 2].map(|i| k[pm.col(i).abs().max_position()]));
    (stretch, scale)
}

/// A unit quaternion with non-negative `w` from a proper rotation matrix.
fn rotation_from_orthonormal(m: &DMat3) -> DQuat {
    let q = DQuat::from_mat3(m).normalize();
    if q.w < 0.0 { -q } else { q }
}

/// Columns `x1×x2, x2×x0, x0×x1`: `det(X)·X⁻ᵀ`.
fn cofactor(x: &DMat3) -> DMat3 {
    DMat3::from_cols(x.y_axis.cross(x.z_axis), x.z_axis.cross(x.x_axis), x.x_axis.cross(x.y_axis))
}

fn symmetric_part(m: &DMat3) -> DMat3 {
    (*m + m.transpose()) * 0.5
}

/// Largest column sum of absolute values.
fn norm_one(m: &DMat3) -> f64 {
    [m.x_axis, m.y_axis, m.z_axis].iter().map(|c| c.abs().element_sum()).fold(0.0, f64::max)
}

/// Largest row sum of absolute values.
fn norm_inf(m: &DMat3) -> f64 {
    norm_one(&m.transpose())
}

fn norm_frobenius(m: &DMat3) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
}

/// The largest deviation from 90°, in degrees, between any two columns of the 3×3 part: 0 for any rotation·scale
/// matrix, whatever its frame. Pairs with a zero column do not count.
pub fn shear_deg(m: &DMat3) -> f64 {
    let cols = [m.x_axis, m.y_axis, m.z_axis];
    let mut worst: f64 = 0.0;
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let (a, b) = (cols[i], cols[j]);
        let lengths = a.length() * b.length();
        if lengths > 0.0 && lengths.is_finite() {
            let cos = (a.dot(b) / lengths).clamp(-1.0, 1.0);
            worst = worst.max((cos.acos().to_degrees() - 90.0).abs());
        }
    }
    worst
}
