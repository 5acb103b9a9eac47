//! The singular value decomposition of a 3×3 matrix, `A·V = U·Σ`, by one-sided (Hestenes) Jacobi rotations.
//!
//! Rotating pairs of columns of `B = A·V` until every pair is orthogonal leaves `B = U·Σ`: the column lengths are
//! the singular values, the normalised columns are `U`, and the accumulated rotations are `V`. Working on the columns
//! of `A` itself, never on `AᵀA`, keeps the small singular values accurate relative to their size (forming `AᵀA`
//! squares the condition number), which is what recomposition at scale ratios up to 1e6 needs.
//!
//! The iteration is a chain of dependent steps, so its cost is the latency of one rotation times their number
//! (about 8 to 10 for a random matrix, some 50 cycles each). Three choices keep it short:
//!
//! - **No square roots, one division.** A rotation only has to be orthogonal, not the exact one that makes the pair
//!   orthogonal. Written through the tangent of its half angle, `τ = tan(φ/2)`, the matrix
//!   `[[1 − τ², 2τ], [−2τ, 1 − τ²]]` is a rotation scaled by `1 + τ²` for *any* `τ`. Instead of dividing the scale
//!   out, the third column is multiplied by it too (off the critical path), so all columns share one growth factor
//!   ([`Jacobi::growth`]), and `τ` comes from a rational approximation of the exact value with a single division
//!   ([`half_angle_tangent`]).
//! - **`V` as a quaternion.** A rotation in the plane of columns `p, q` turns about the third axis, and its
//!   quaternion is `(τ·axis, 1)` up to scale: four multiply-adds per rotation and one normalisation at the end.
//! - **All three pairs at once near the end.** Cyclic sweeps (pair after pair) converge from anywhere. Once every
//!   pair needs only a small turn, the three turns commute up to terms of their products' size, so they are taken
//!   together ([`Jacobi::turn_all`]): one rotation built from three half-angle tangents computed side by side, which
//!   converges quadratically too, at about half the latency of a sweep.

use glam::DQuat;

/// A column of a 3×3 matrix.
pub(super) type Col = [f64; 3];

/// Two columns count as orthogonal when the cosine of their angle is at most this: about 4.5ε, just above what the
/// cosine of two computed columns can reliably get below (a few units of rounding). Looser values stop earlier but
/// leave their cosine in the polar factor (measured: 4e-15 makes the worst recomposition error 3× larger).
const ORTHOGONAL_COSINE: f64 = 1e-15;

/// Iteration cap (sweeps and simultaneous steps). Random matrices need 3 to 6, rank-deficient ones up to 10;
/// rounding can keep a cosine from settling below [`ORTHOGONAL_COSINE`] only in contrived cases, where the cap ends
/// the loop.
const MAX_STEPS: usize = 16;

/// The three turns are taken at once when every pair's `|x| = |γ|/|β − α|` (about the angle each needs) is at most
/// this: what one pair's turn then changes in another's is of the order of `x²`, below what the step removes.
/// Larger values take the simultaneous step earlier and need more of them (measured: 0.01 is the fastest and keeps
/// recomposition at rounding level).
const SIMULTANEOUS_TURN: f64 = 0.01;

/// A column whose squared length is at most this fraction of the largest one is treated as zero: its direction in
/// `U` is completed from the others. Far below anything a cosine test on squared lengths could resolve.
const NULL_RATIO_SQUARED: f64 = 1e-200;

/// `A = sign·U·Σ·Vᵀ` with `U` and `V` rotations: the SVD with the sign of the determinant taken out of `U`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Svd {
    /// `−1` when `det A < 0`, else `1` (also `1` when a singular value is zero: `U` is then completed as a rotation).
    pub sign: f64,
    /// The columns of `U`, orthonormal with `det U = +1`.
    pub u: [Col; 3],
    /// The singular values `σᵢ ≥ 0`, in the order of `U`'s and `V`'s columns (not sorted).
    pub sigma: [f64; 3],
    /// The rotation `V` as a unit quaternion; exactly the identity when `A`'s columns were orthogonal already.
    pub v: DQuat,
}

/// The SVD of `a` (columns). `a` must be finite.
///
/// `start` is where the search for `V` begins: the identity, or a rotation close to the answer (the stretch frame of
/// the same bone one frame earlier), from which the columns are nearly orthogonal and one or two simultaneous turns
/// finish the job instead of three or four sweeps. Any start converges to the same result; a far one only costs
/// steps.
pub(super) fn svd(a: &[Col; 3], start: DQuat, already_orthogonal: impl Fn(&Gram) -> bool) -> Svd {
    let (a, exponent) = rescaled(a);
    let mut jacobi = Jacobi { b: a, v: DQuat::IDENTITY, growth: 1.0 };
    let mut gram = Gram::of(&a);
    if !already_orthogonal(&gram) {
        if start != DQuat::IDENTITY && start.is_finite() {
            jacobi.start_at(start.normalize());
            gram = Gram::of(&jacobi.b);
        }
        for _ in 0..MAX_STEPS {
            if gram.orthogonal() {
                break;
            }
            if gram.small_turns() {
                jacobi.turn_all(&gram);
            } else {
                jacobi.sweep();
            }
            gram = Gram::of(&jacobi.b);
        }
    }
    jacobi.finish(exponent)
}

/// Squared column lengths and pairwise dot products.
#[derive(Clone, Copy, Debug)]
pub(super) struct Gram {
    /// `|aᵢ|²`.
    pub lengths_squared: [f64; 3],
    /// `a₀·a₁, a₀·a₂, a₁·a₂`.
    pub dots: [f64; 3],
}

impl Gram {
    fn of(a: &[Col; 3]) -> Self {
        Gram { lengths_squared: a.map(|c| dot(c, c)), dots: [dot(a[0], a[1]), dot(a[0], a[2]), dot(a[1], a[2])] }
    }

    /// The pairs (0, 1), (0, 2), (1, 2) as `(α, β, γ)`: squared lengths and dot product.
    fn pairs(&self) -> [(f64, f64, f64); 3] {
        let ([a0, a1, a2], [g01, g02, g12]) = (self.lengths_squared, self.dots);
        [(a0, a1, g01), (a0, a2, g02), (a1, a2, g12)]
    }

    /// Whether every pair is orthogonal to within [`ORTHOGONAL_COSINE`].
    fn orthogonal(&self) -> bool {
        let [p, q, r] = self.pairs().map(|(alpha, beta, gamma)| cosine_negligible(alpha, beta, gamma));
        p & q & r
    }

    /// Whether every pair needs only a small turn (see [`SIMULTANEOUS_TURN`]).
    fn small_turns(&self) -> bool {
        let x2 = SIMULTANEOUS_TURN * SIMULTANEOUS_TURN;
        let [p, q, r] = self.pairs().map(|(alpha, beta, gamma)| gamma * gamma <= x2 * (beta - alpha) * (beta - alpha));
        p & q & r
    }
}

/// `a` scaled by a power of two (exactly) so that its largest entry is near 1 when it is far from it, and the
/// exponent to scale the singular values back by. Keeps the products of squared lengths in [`half_angle_tangent`]
/// and [`cosine_negligible`] (fourth powers of the entries) clear of overflow and underflow for any finite input.
fn rescaled(a: &[Col; 3]) -> ([Col; 3], i32) {
    let largest = a.iter().flatten().fold(0.0, |m: f64, x| m.max(x.abs()));
    if (1e-30..=1e30).contains(&largest) || largest == 0.0 {
        return (*a, 0);
    }
    let exponent = largest.log2().round() as i32;
    (a.map(|c| c.map(|x| times_power_of_two(x, -exponent))), exponent)
}

/// `x·2^exponent` in two steps, so that neither factor overflows (the exponent of a subnormal is below −1022).
fn times_power_of_two(x: f64, exponent: i32) -> f64 {
    let half = exponent / 2;
    x * 2f64.powi(half) * 2f64.powi(exponent - half)
}

/// The iteration's state: `b = growth·A·V`.
struct Jacobi {
    b: [Col; 3],
    /// `V`, unnormalised (each rotation scales it by `√(1 + τ²)`).
    v: DQuat,
    /// How much the unnormalised rotations have scaled `b`: the product of their `1 + τ²`.
    growth: f64,
}

impl Jacobi {
    /// Begins at `V = start` (a unit quaternion): `b = A·R(start)`.
    fn start_at(&mut self, start: DQuat) {
        let r = glam::DMat3::from_quat(start).to_cols_array_2d();
        let a = self.b;
        self.b =
            std::array::from_fn(|j| std::array::from_fn(|i| a[0][i] * r[j][0] + a[1][i] * r[j][1] + a[2][i] * r[j][2]));
        self.v = start;
    }

    /// One cyclic sweep over the three pairs.
    fn sweep(&mut self) {
        // A rotation in the (p, q) plane turns about the third axis k: by −φ when (p, q, k) is cyclic, else by +φ.
        self.rotate::<0, 1, 2>(-1.0);
        self.rotate::<0, 2, 1>(1.0);
        self.rotate::<1, 2, 0>(-1.0);
    }

    /// Makes columns P and Q (nearly) orthogonal, unless they are already.
    #[inline(always)]
    fn rotate<const P: usize, const Q: usize, const K: usize>(&mut self, turn: f64) {
        let (p, q) = (self.b[P], self.b[Q]);
        let (alpha, beta, gamma) = (dot(p, p), dot(q, q), dot(p, q));
        if cosine_negligible(alpha, beta, gamma) {
            return;
        }
        let tau = half_angle_tangent(alpha, beta, gamma);
        let (c, s) = (1.0 - tau * tau, 2.0 * tau);
        self.b[P] = std::array::from_fn(|i| c * p[i] - s * q[i]);
        self.b[Q] = std::array::from_fn(|i| s * p[i] + c * q[i]);
        // Columns P and Q grew by 1 + τ²; K follows so that all three keep one common scale.
        let growth = 1.0 + tau * tau;
        self.b[K] = self.b[K].map(|x| x * growth);
        self.growth *= growth;
        self.v = turned::<K>(self.v, turn * tau);
    }

    /// The turns of all three pairs at once, each computed from `gram` as if it were alone: the rotation whose
    /// quaternion is `(t, 1)` with `t` the three signed half-angle tangents (turn about k for the pair (p, q), as in
    /// [`Jacobi::sweep`]). Its matrix `|q|²·R` is `(1 − |t|²)·I + 2·t·tᵀ + 2·[t]×`, exact up to rounding.
    fn turn_all(&mut self, gram: &Gram) {
        let [t01, t02, t12] = gram.pairs().map(|(alpha, beta, gamma)| half_angle_tangent(alpha, beta, gamma));
        let [x, y, z] = [-t12, t02, -t01];
        let (xx, yy, zz, xy, xz, yz) = (x * x, y * y, z * z, x * y, x * z, y * z);
        let squared = xx + yy + zz;
        // Columns: the images of the axes.
        let m: [Col; 3] = [
            [1.0 - squared + 2.0 * xx, 2.0 * (xy + z), 2.0 * (xz - y)],
            [2.0 * (xy - z), 1.0 - squared + 2.0 * yy, 2.0 * (yz + x)],
            [2.0 * (xz + y), 2.0 * (yz - x), 1.0 - squared + 2.0 * zz],
        ];
        let b = self.b;
        self.b =
            std::array::from_fn(|j| std::array::from_fn(|i| b[0][i] * m[j][0] + b[1][i] * m[j][1] + b[2][i] * m[j][2]));
        self.growth *= 1.0 + squared;
        self.v *= DQuat::from_xyzw(x, y, z, 1.0);
    }

    /// `U` and `Σ` from the columns, `V` normalised; singular values scaled back by `2^exponent`.
    fn finish(self, exponent: i32) -> Svd {
        let b = self.b;
        let lengths_squared = b.map(|c| dot(c, c));
        let largest = lengths_squared[0].max(lengths_squared[1]).max(lengths_squared[2]);
        let null = lengths_squared.map(|l| l <= largest * NULL_RATIO_SQUARED);
        let lengths = lengths_squared.map(f64::sqrt);
        // det B = det A·growth³ has the sign of det A, and takes less time than the lengths it runs beside. With a
        // zero singular value the sign is free: U is completed as a rotation below.
        let any_null = null.iter().any(|&n| n);
        let sign = if dot(b[0], cross(b[1], b[2])) < 0.0 && !any_null { -1.0 } else { 1.0 };
        let shrink = 1.0 / self.growth;
        let mut sigma = lengths.map(|l| l * shrink);
        if exponent != 0 {
            sigma = sigma.map(|s| times_power_of_two(s, exponent));
        }
        let mut u: [Col; 3] = std::array::from_fn(|i| {
            let inverse = if null[i] { 0.0 } else { sign / lengths[i] };
            b[i].map(|x| x * inverse)
        });
        if any_null {
            complete(&mut u, null);
        }
        let v = if self.v == DQuat::IDENTITY { self.v } else { self.v.normalize() };
        Svd { sign, u, sigma, v }
    }
}

/// Fills the columns of `u` marked `null` so that `u` is a rotation (`det = +1`).
fn complete(u: &mut [Col; 3], null: [bool; 3]) {
    match null.iter().filter(|&&n| n).count() {
        1 => {
            let k = null.iter().position(|&n| n).unwrap_or(2);
            u[k] = cross(u[(k + 1) % 3], u[(k + 2) % 3]);
        }
        2 => {
            let i = null.iter().position(|&n| !n).unwrap_or(0);
            let first = glam::DVec3::from_array(u[i]);
            let second = first.any_orthonormal_vector();
            u[(i + 1) % 3] = second.to_array();
            u[(i + 2) % 3] = first.cross(second).to_array();
        }
        _ => *u = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    }
}

// The rational approximation of the half-angle tangent, `τ ≈ x·(1 + B·|x|) / (2 + 2B·|x| + E·x²)`. It agrees with the
// exact `x/2` to first order at 0 (so the leftover dot product is about `0.8·x²` of what it was: quadratic
// convergence), and its limit for `|x| → ∞` is the exact `tan(π/8)` (so `B = E·tan(π/8)`). `E` minimises the worst
// leftover over all `x`: after a rotation the pair's dot product is at most 2 % of what it was. A third-degree
// version leaves less (0.15 %) and saves a rotation in ten, but its longer chain of multiplications costs more.
const E: f64 = 4.136;
const B: f64 = E * (std::f64::consts::SQRT_2 - 1.0);

/// `τ ≈ tan(φ/2)` for the rotation that makes two columns orthogonal, from their squared lengths `alpha`, `beta`
/// and dot product `gamma`; 0 when they are orthogonal already (or both negligible).
///
/// Turning column p by `−φ` towards q gives a dot product `γ·cos 2φ − ((β − α)/2)·sin 2φ`, zero for
/// `tan 2φ = 2x` with `x = γ/(β − α)`, so the exact value is `τ = tan(¼·atan 2x)`, |φ| ≤ 45°. The approximation is
/// written homogeneously in `e = |β − α|` and `g = |γ|` (numerator and denominator multiplied by `e²`), which takes
/// the division by `β − α` out and leaves one division in all.
#[inline(always)]
fn half_angle_tangent(alpha: f64, beta: f64, gamma: f64) -> f64 {
    let d = beta - alpha;
    let (e, g) = (d.abs(), gamma.abs());
    let numerator = e + B * g;
    let denominator = 2.0 * e * numerator + E * g * g;
    // The sign of τ is that of x: of γ, flipped when β < α.
    let tau = g.copysign(gamma * d) * numerator / denominator;
    if cosine_negligible(alpha, beta, gamma) || denominator <= 0.0 { 0.0 } else { tau }
}

/// Whether columns with squared lengths `alpha`, `beta` and dot product `gamma` are orthogonal to within
/// [`ORTHOGONAL_COSINE`].
#[inline(always)]
fn cosine_negligible(alpha: f64, beta: f64, gamma: f64) -> bool {
    gamma * gamma <= ORTHOGONAL_COSINE * ORTHOGONAL_COSINE * alpha * beta
}

/// `q ⊗ (t·e_K, 1)`: `q` followed by a turn about axis K whose quaternion is `(t·e_K, 1)` up to scale.
#[inline(always)]
fn turned<const K: usize>(q: DQuat, t: f64) -> DQuat {
    // With (i, j, K) cyclic: v × e_K has v_j at i and −v_i at j.
    let (i, j) = ((K + 1) % 3, (K + 2) % 3);
    let v = [q.x, q.y, q.z];
    let mut out = v;
    out[i] = v[i] + t * v[j];
    out[j] = v[j] - t * v[i];
    out[K] = v[K] + t * q.w;
    DQuat::from_xyzw(out[0], out[1], out[2], q.w - t * v[K])
}

#[inline(always)]
pub(super) fn dot(a: Col, b: Col) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub(super) fn cross(a: Col, b: Col) -> Col {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use glam::{DMat3, DVec3};

    use super::*;

    fn matrix(cols: &[Col; 3]) -> DMat3 {
        DMat3::from_cols_array_2d(cols)
    }

    fn recomposed(s: &Svd) -> DMat3 {
        let v = DMat3::from_quat(s.v);
        matrix(&s.u) * DMat3::from_diagonal(DVec3::from_array(s.sigma)) * v.transpose() * s.sign
    }

    fn never(_: &Gram) -> bool {
        false
    }

    #[test]
    fn half_angle_tangent_is_close_to_exact() {
        for x in [1e-6, 1e-3, 0.1, 0.5, 1.0, 3.0, 100.0, 1e6f64] {
            for (alpha, sign) in [(1.0, 1.0), (3.0, -1.0)] {
                let beta = alpha + sign * 1.0;
                let gamma = x * (beta - alpha);
                let exact = (0.25 * (2.0 * x).atan()).tan();
                let tau = half_angle_tangent(alpha, beta, gamma);
                assert!((tau - exact).abs() <= 2e-2 * exact.abs(), "x {x}: {tau} vs {exact}");
            }
        }
        assert_eq!(half_angle_tangent(1.0, 2.0, 1e-16), 0.0);
        assert!((half_angle_tangent(2.0, 2.0, 0.5) - (std::f64::consts::PI / 8.0).tan()).abs() < 1e-15);
    }

    #[test]
    fn turned_matches_quaternion_product() {
        let q = DQuat::from_xyzw(0.1, -0.7, 0.3, 0.6);
        let t = 0.37;
        assert!(turned::<0>(q, t).abs_diff_eq(q * DQuat::from_xyzw(t, 0.0, 0.0, 1.0), 1e-15));
        assert!(turned::<1>(q, t).abs_diff_eq(q * DQuat::from_xyzw(0.0, t, 0.0, 1.0), 1e-15));
        assert!(turned::<2>(q, t).abs_diff_eq(q * DQuat::from_xyzw(0.0, 0.0, t, 1.0), 1e-15));
    }

    #[test]
    fn decomposes_a_general_matrix() {
        let a = [[1.0, 2.0, 0.5], [-1.0, 0.5, 2.0], [0.3, 2.5, -2.5]];
        let s = svd(&a, DQuat::IDENTITY, never);
        assert!(recomposed(&s).abs_diff_eq(matrix(&a), 1e-14));
        let u = matrix(&s.u);
        assert!((u.transpose() * u).abs_diff_eq(DMat3::IDENTITY, 1e-15));
        assert!(u.determinant() > 0.0 && s.sign == matrix(&a).determinant().signum());
        let mirrored = [a[0], a[1], a[2].map(|x| -x)];
        let m = svd(&mirrored, DQuat::IDENTITY, never);
        assert!(recomposed(&m).abs_diff_eq(matrix(&mirrored), 1e-14));
        assert!(matrix(&m.u).determinant() > 0.0 && m.sign == -s.sign);
        assert!(s.sigma.iter().all(|&x| x > 0.0));
    }

    #[test]
    fn rescales_huge_and_tiny_matrices() {
        for factor in [1e-200, 1e200] {
            let a = [[1.0, 2.0, 0.5], [-1.0, 0.5, 2.0], [0.3, 2.5, -2.5]].map(|c: Col| c.map(|x| x * factor));
            let s = svd(&a, DQuat::IDENTITY, never);
            let error = (recomposed(&s) - matrix(&a)).to_cols_array().iter().fold(0.0, |m: f64, x| m.max(x.abs()));
            assert!(error <= 1e-14 * factor, "{factor}: {error}");
        }
    }

    #[test]
    fn completes_null_columns_to_a_rotation() {
        let s = svd(&[[0.0; 3], [0.0, 2.0, 0.0], [0.0; 3]], DQuat::IDENTITY, never);
        assert!(matrix(&s.u).determinant() > 0.999_999);
        assert_eq!(s.sigma, [0.0, 2.0, 0.0]);
        let s = svd(&[[0.0; 3]; 3], DQuat::IDENTITY, never);
        assert_eq!(matrix(&s.u), DMat3::IDENTITY);
        // A mirroring rank-2 matrix: the sign is free, U a rotation, and the recomposition exact.
        let a = [[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, 0.0, 2.0]];
        let s = svd(&a, DQuat::IDENTITY, never);
        assert_eq!(s.sign, 1.0);
        assert!(matrix(&s.u).determinant() > 0.999_999);
        assert!(recomposed(&s).abs_diff_eq(matrix(&a), 1e-15));
    }
}
