//! The singular value decomposition of a 3×3 matrix, `A·V = W·Σ`, by one-sided (Hestenes) Jacobi rotations.
//!
//! Rotating pairs of columns of `B = A·V` until every pair is orthogonal leaves `B = W·Σ`: the column lengths are
//! the singular values, the normalised columns are `W`, and the accumulated rotations are `V`. Working on the columns
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
//!
//! Because the chain leaves most of the processor idle, [`svd_each`] runs two matrices through it at once, one in
//! each lane of SIMD registers: the iteration is written once over [`Lanes`] (one `f64`, or two in an `f64x2`).

use glam::DQuat;
use wide::f64x2;

use super::lanes::Lanes;
use super::rotation::{Cols, Quat, matrix_of, product, quat_from_rotation, times, times_transpose};

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
/// `W` is completed from the others. Far below anything a cosine test on squared lengths could resolve.
const NULL_RATIO_SQUARED: f64 = 1e-200;

/// `A = sign·W·Σ·Vᵀ` with `W` and `V` rotations: the SVD with the sign of the determinant taken out of `W`, given
/// as what the polar decomposition needs: `Σ`, `V` and the rotation `R = W·Vᵀ` of the polar factor (`W = R·V`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Svd {
    /// `−1` when `det A < 0`, else `1` (also `1` when a singular value is zero: `W` is then completed as a rotation).
    pub sign: f64,
    /// The singular values `σᵢ ≥ 0`, in the order of `W`'s and `V`'s columns (not sorted).
    pub sigma: [f64; 3],
    /// The rotation `V` as a unit quaternion; exactly the identity when `A`'s columns were orthogonal already.
    pub v: DQuat,
    /// `R = W·Vᵀ` as a unit quaternion with `w ≥ 0`.
    pub rotation: DQuat,
}

/// The SVD of `a` (columns). `a` must be finite.
///
/// `start` is where the search for `V` begins: the identity, or a rotation close to the answer (the stretch frame of
/// the same bone one frame earlier), from which the columns are nearly orthogonal and one or two simultaneous turns
/// finish the job instead of three or four sweeps. Any start converges to the same result; a far one only costs
/// steps. When `already_orthogonal` says so of `a`'s columns, `V` is the identity without a search.
pub(super) fn svd(a: &[Col; 3], start: DQuat, already_orthogonal: impl Fn(&Gram) -> bool) -> Svd {
    let (a, exponent) = rescaled(a);
    if already_orthogonal(&Gram::of(&a)) {
        return Jacobi::at_identity(a).finished(Turned::No).svd(exponent);
    }
    let mut jacobi = Jacobi::starting_at(a, start);
    jacobi.iterate();
    jacobi.finished(Turned::Yes).svd(exponent)
}

/// [`svd`] of every matrix (from the identity), each result handed to `found` with its index; those that need a
/// search go two at a time, one in each lane of SIMD registers ([`Lanes`]), where a pair costs little more than
/// one. The two take their sweeps and simultaneous turns together (a lane that has converged turns by exactly
/// nothing), so a result may differ from [`svd`]'s by rounding.
pub(super) fn svd_each(
    matrices: impl Iterator<Item = [Col; 3]>,
    already_orthogonal: impl Fn(&Gram) -> bool,
    mut found: impl FnMut(usize, Svd),
) {
    let mut waiting: Option<(usize, Jacobi<f64>, i32)> = None;
    for (index, a) in matrices.enumerate() {
        let (a, exponent) = rescaled(&a);
        let jacobi = Jacobi::at_identity(a);
        if already_orthogonal(&Gram::of(&a)) {
            found(index, jacobi.finished(Turned::No).svd(exponent));
            continue;
        }
        match waiting.take() {
            None => waiting = Some((index, jacobi, exponent)),
            Some((other_index, other, other_exponent)) => {
                let mut pair = Jacobi::pair([other, jacobi]);
                pair.iterate();
                let [first, second] = pair.finished(Turned::Yes).lanes();
                found(other_index, first.svd(other_exponent));
                found(index, second.svd(exponent));
            }
        }
    }
    if let Some((index, mut jacobi, exponent)) = waiting {
        jacobi.iterate();
        found(index, jacobi.finished(Turned::Yes).svd(exponent));
    }
}

/// Squared column lengths and pairwise dot products.
#[derive(Clone, Copy, Debug)]
pub(super) struct Gram<L = f64> {
    /// `|aᵢ|²`.
    pub lengths_squared: [L; 3],
    /// `a₀·a₁, a₀·a₂, a₁·a₂`.
    pub dots: [L; 3],
}

impl<L: Lanes> Gram<L> {
    #[inline(always)]
    fn of(a: &Cols<L>) -> Self {
        Gram { lengths_squared: a.map(|c| dot(c, c)), dots: [dot(a[0], a[1]), dot(a[0], a[2]), dot(a[1], a[2])] }
    }

    /// The pairs (0, 1), (0, 2), (1, 2) as `(α, β, γ)`: squared lengths and dot product.
    #[inline(always)]
    fn pairs(&self) -> [(L, L, L); 3] {
        let ([a0, a1, a2], [g01, g02, g12]) = (self.lengths_squared, self.dots);
        [(a0, a1, g01), (a0, a2, g02), (a1, a2, g12)]
    }

    /// Whether every pair is orthogonal to within [`ORTHOGONAL_COSINE`].
    #[inline(always)]
    fn orthogonal(&self) -> L::Mask {
        let [p, q, r] = self.pairs().map(|(alpha, beta, gamma)| cosine_negligible(alpha, beta, gamma));
        p & q & r
    }

    /// Whether every pair needs only a small turn (see [`SIMULTANEOUS_TURN`]).
    #[inline(always)]
    fn small_turns(&self) -> L::Mask {
        let x2 = L::splat(SIMULTANEOUS_TURN * SIMULTANEOUS_TURN);
        let [p, q, r] =
            self.pairs().map(|(alpha, beta, gamma)| (gamma * gamma).le(x2 * (beta - alpha) * (beta - alpha)));
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

/// The iteration's state: `b = growth·A·V`, one matrix per lane.
struct Jacobi<L> {
    b: Cols<L>,
    /// `V`, unnormalised (each rotation scales it by `√(1 + τ²)`).
    v: Quat<L>,
    /// How much the unnormalised rotations have scaled `b`: the product of their `1 + τ²`.
    growth: L,
}

impl Jacobi<f64> {
    fn at_identity(a: [Col; 3]) -> Self {
        Jacobi { b: a, v: [0.0, 0.0, 0.0, 1.0], growth: 1.0 }
    }

    /// Begins at `V = start` when it is a usable rotation other than the identity: `b = A·R(start)`.
    fn starting_at(a: [Col; 3], start: DQuat) -> Self {
        if start == DQuat::IDENTITY || !start.is_finite() {
            return Self::at_identity(a);
        }
        let v = start.normalize().to_array();
        Jacobi { b: times(&a, &matrix_of(v)), v, growth: 1.0 }
    }
}

impl Jacobi<f64x2> {
    /// Two matrices' states side by side.
    fn pair([first, second]: [Jacobi<f64>; 2]) -> Self {
        let join = |x: f64, y: f64| f64x2::from([x, y]);
        Jacobi {
            b: std::array::from_fn(|j| std::array::from_fn(|i| join(first.b[j][i], second.b[j][i]))),
            v: std::array::from_fn(|i| join(first.v[i], second.v[i])),
            growth: join(first.growth, second.growth),
        }
    }
}

impl<L: Lanes> Jacobi<L> {
    /// Cyclic sweeps until every pair needs only a small turn, then simultaneous turns, until every pair is
    /// orthogonal (in every lane).
    #[inline(always)]
    fn iterate(&mut self) {
        for _ in 0..MAX_STEPS {
            let gram = Gram::of(&self.b);
            if L::all(gram.orthogonal()) {
                break;
            }
            if L::all(gram.small_turns()) {
                self.turn_all(&gram);
            } else {
                self.sweep();
            }
        }
    }

    /// One cyclic sweep over the three pairs.
    #[inline(always)]
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
        if L::all(cosine_negligible(alpha, beta, gamma)) {
            return;
        }
        let tau = half_angle_tangent(alpha, beta, gamma);
        let (c, s) = (L::splat(1.0) - tau * tau, L::splat(2.0) * tau);
        self.b[P] = std::array::from_fn(|i| c * p[i] - s * q[i]);
        self.b[Q] = std::array::from_fn(|i| s * p[i] + c * q[i]);
        // Columns P and Q grew by 1 + τ²; K follows so that all three keep one common scale.
        let growth = L::splat(1.0) + tau * tau;
        self.b[K] = self.b[K].map(|x| x * growth);
        self.growth = self.growth * growth;
        self.v = turned::<L, K>(self.v, L::splat(turn) * tau);
    }

    /// The turns of all three pairs at once, each computed from `gram` as if it were alone: the rotation whose
    /// quaternion is `(t, 1)` with `t` the three signed half-angle tangents (turn about k for the pair (p, q), as in
    /// [`Jacobi::sweep`]). Its matrix `|q|²·R` is `(1 − |t|²)·I + 2·t·tᵀ + 2·[t]×`, exact up to rounding.
    #[inline(always)]
    fn turn_all(&mut self, gram: &Gram<L>) {
        let [t01, t02, t12] = gram.pairs().map(|(alpha, beta, gamma)| half_angle_tangent(alpha, beta, gamma));
        let [x, y, z] = [-t12, t02, -t01];
        let (xx, yy, zz, xy, xz, yz) = (x * x, y * y, z * z, x * y, x * z, y * z);
        let squared = xx + yy + zz;
        let (one, two) = (L::splat(1.0), L::splat(2.0));
        // Columns: the images of the axes.
        let m: Cols<L> = [
            [one - squared + two * xx, two * (xy + z), two * (xz - y)],
            [two * (xy - z), one - squared + two * yy, two * (yz + x)],
            [two * (xz + y), two * (yz - x), one - squared + two * zz],
        ];
        self.b = times(&self.b, &m);
        self.growth = self.growth * (one + squared);
        self.v = product(self.v, [x, y, z, one]);
    }

    /// `Σ`, `V` (normalised) and `R = W·Vᵀ` from the columns, with `W` their directions; when some columns are
    /// null, [`Finished::svd`] completes `W`. `turned` says whether `V` may differ from the identity.
    #[inline(always)]
    fn finished(self, turned: Turned) -> Finished<L> {
        let b = self.b;
        let lengths_squared = b.map(|c| dot(c, c));
        let largest = lengths_squared[0].max(lengths_squared[1]).max(lengths_squared[2]);
        let null = lengths_squared.map(|l| l.le(largest * L::splat(NULL_RATIO_SQUARED)));
        let any_null = null[0] | null[1] | null[2];
        let lengths = lengths_squared.map(L::sqrt);
        // det B = det A·growth³ has the sign of det A, and takes less time than the lengths it runs beside. With a
        // zero singular value the sign is free: W is completed as a rotation.
        let (one, zero) = (L::splat(1.0), L::splat(0.0));
        let mirrored = dot(b[0], cross(b[1], b[2])).lt(zero);
        let sign = L::select(any_null, one, L::select(mirrored, -one, one));
        let shrink = one / self.growth;
        let w: Cols<L> = std::array::from_fn(|i| {
            let inverse = L::select(null[i], zero, sign / lengths[i]);
            b[i].map(|x| x * inverse)
        });
        let [x, y, z, s] = self.v;
        let v = self.v.map(|c| c * (one / (x * x + y * y + z * z + s * s).sqrt()));
        let rotation = match turned {
            Turned::No => quat_from_rotation(&w),
            Turned::Yes => polar_rotation(&w, v),
        };
        Finished { sign, sigma: lengths.map(|l| l * shrink), v, rotation, w, null }
    }
}

/// Whether the iteration turned `V` away from the identity (the shortcut's columns are taken as they are).
#[derive(Clone, Copy)]
enum Turned {
    No,
    Yes,
}

/// [`Jacobi::finished`]: the SVD's parts in lanes, before the rare completions.
struct Finished<L: Lanes> {
    sign: L,
    /// Not yet scaled back by the exponent of [`rescaled`].
    sigma: [L; 3],
    v: Quat<L>,
    rotation: Quat<L>,
    /// The normalised columns, zero where `null`.
    w: Cols<L>,
    /// Which columns are null (their direction in `W` is free).
    null: [L::Mask; 3],
}

impl Finished<f64> {
    /// The [`Svd`], with singular values scaled back by `2^exponent` and, where columns were null, `W` completed
    /// as a rotation and `R` taken from it.
    fn svd(self, exponent: i32) -> Svd {
        let mut sigma = self.sigma;
        if exponent != 0 {
            sigma = sigma.map(|s| times_power_of_two(s, exponent));
        }
        let mut rotation = self.rotation;
        if self.null.iter().any(|&n| n) {
            let mut w = self.w;
            complete(&mut w, self.null);
            rotation = polar_rotation(&w, self.v);
        }
        Svd { sign: self.sign, sigma, v: DQuat::from_array(self.v), rotation: DQuat::from_array(rotation) }
    }
}

impl Finished<f64x2> {
    /// The two matrices' parts apart.
    fn lanes(self) -> [Finished<f64>; 2] {
        std::array::from_fn(|lane| {
            let pick = |x: f64x2| x.to_array()[lane];
            Finished {
                sign: pick(self.sign),
                sigma: self.sigma.map(pick),
                v: self.v.map(pick),
                rotation: self.rotation.map(pick),
                w: self.w.map(|c| c.map(pick)),
                null: self.null.map(|n| n.to_bitmask() >> lane & 1 == 1),
            }
        })
    }
}

/// The quaternion of `R = W·Vᵀ`, the rotation of the polar factor.
#[inline(always)]
fn polar_rotation<L: Lanes>(w: &Cols<L>, v: Quat<L>) -> Quat<L> {
    quat_from_rotation(&times_transpose(w, &matrix_of(v)))
}

/// Fills the columns of `w` marked `null` so that `w` is a rotation (`det = +1`).
fn complete(w: &mut [Col; 3], null: [bool; 3]) {
    match null.iter().filter(|&&n| n).count() {
        1 => {
            let k = null.iter().position(|&n| n).unwrap_or(2);
            w[k] = cross(w[(k + 1) % 3], w[(k + 2) % 3]);
        }
        2 => {
            let i = null.iter().position(|&n| !n).unwrap_or(0);
            let first = glam::DVec3::from_array(w[i]);
            let second = first.any_orthonormal_vector();
            w[(i + 1) % 3] = second.to_array();
            w[(i + 2) % 3] = first.cross(second).to_array();
        }
        _ => *w = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
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
fn half_angle_tangent<L: Lanes>(alpha: L, beta: L, gamma: L) -> L {
    let d = beta - alpha;
    let (e, g) = (d.abs(), gamma.abs());
    let numerator = e + L::splat(B) * g;
    let denominator = L::splat(2.0) * e * numerator + L::splat(E) * g * g;
    // The sign of τ is that of x: of γ, flipped when β < α.
    let tau = gamma.times_sign_of(d) * numerator / denominator;
    let none = cosine_negligible(alpha, beta, gamma) | denominator.le(L::splat(0.0));
    L::select(none, L::splat(0.0), tau)
}

/// Whether columns with squared lengths `alpha`, `beta` and dot product `gamma` are orthogonal to within
/// [`ORTHOGONAL_COSINE`].
#[inline(always)]
fn cosine_negligible<L: Lanes>(alpha: L, beta: L, gamma: L) -> L::Mask {
    (gamma * gamma).le(L::splat(ORTHOGONAL_COSINE * ORTHOGONAL_COSINE) * alpha * beta)
}

/// `q ⊗ (t·e_K, 1)`: `q` followed by a turn about axis K whose quaternion is `(t·e_K, 1)` up to scale.
#[inline(always)]
fn turned<L: Lanes, const K: usize>(q: Quat<L>, t: L) -> Quat<L> {
    // With (i, j, K) cyclic: v × e_K has v_j at i and −v_i at j.
    let (i, j) = ((K + 1) % 3, (K + 2) % 3);
    let mut out = q;
    out[i] = q[i] + t * q[j];
    out[j] = q[j] - t * q[i];
    out[K] = q[K] + t * q[3];
    out[3] = q[3] - t * q[K];
    out
}

#[inline(always)]
fn dot<L: Lanes>(a: [L; 3], b: [L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross<L: Lanes>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use glam::{DMat3, DVec3};

    use super::*;

    fn matrix(cols: &[Col; 3]) -> DMat3 {
        DMat3::from_cols_array_2d(cols)
    }

    /// `W = R·V`.
    fn w(s: &Svd) -> DMat3 {
        DMat3::from_quat(s.rotation * s.v)
    }

    fn recomposed(s: &Svd) -> DMat3 {
        let v = DMat3::from_quat(s.v);
        w(s) * DMat3::from_diagonal(DVec3::from_array(s.sigma)) * v.transpose() * s.sign
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
    fn turns_match_quaternion_products() {
        let q = DQuat::from_xyzw(0.1, -0.7, 0.3, 0.6);
        let t = 0.37;
        let turns =
            [turned::<f64, 0>(q.to_array(), t), turned::<f64, 1>(q.to_array(), t), turned::<f64, 2>(q.to_array(), t)];
        for (turn, axis) in turns.into_iter().zip([DVec3::X, DVec3::Y, DVec3::Z]) {
            let expected = q * DQuat::from_vec4((axis * t).extend(1.0));
            assert!(DQuat::from_array(turn).abs_diff_eq(expected, 1e-15), "{axis}");
        }
    }

    #[test]
    fn decomposes_a_general_matrix() {
        let a = [[1.0, 2.0, 0.5], [-1.0, 0.5, 2.0], [0.3, 2.5, -2.5]];
        let s = svd(&a, DQuat::IDENTITY, never);
        assert!(recomposed(&s).abs_diff_eq(matrix(&a), 1e-14));
        let u = w(&s);
        assert!((u.transpose() * u).abs_diff_eq(DMat3::IDENTITY, 1e-15));
        assert!(u.determinant() > 0.0 && s.sign == matrix(&a).determinant().signum());
        let mirrored = [a[0], a[1], a[2].map(|x| -x)];
        let m = svd(&mirrored, DQuat::IDENTITY, never);
        assert!(recomposed(&m).abs_diff_eq(matrix(&mirrored), 1e-14));
        assert!(w(&m).determinant() > 0.0 && m.sign == -s.sign);
        assert!(s.sigma.iter().all(|&x| x > 0.0));
    }

    /// Two lanes compute what one does: a matrix beside itself gives its own SVD bit for bit, and a matrix that
    /// needs no turn beside one that needs many is left exactly as it was.
    #[test]
    fn lanes_give_the_single_results() {
        let a = [[1.0, 2.0, 0.5], [-1.0, 0.5, 2.0], [0.3, 2.5, -2.5]];
        let orthogonal = [[2.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 3.0, 0.0]];
        let mut found = Vec::new();
        svd_each([a, a, a, orthogonal].into_iter(), never, |i, s| found.push((i, s)));
        found.sort_by_key(|&(i, _)| i);
        let single = svd(&a, DQuat::IDENTITY, never);
        assert_eq!(found[0].1, single);
        assert_eq!(found[1].1, single);
        assert_eq!(found[2].1.sigma, single.sigma);
        assert_eq!(found[3].1, svd(&orthogonal, DQuat::IDENTITY, never));
        assert_eq!(found[3].1.v, DQuat::IDENTITY);
        assert!(recomposed(&found[2].1).abs_diff_eq(matrix(&a), 1e-14));
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
        assert!(w(&s).determinant() > 0.999_999);
        assert_eq!(s.sigma, [0.0, 2.0, 0.0]);
        let s = svd(&[[0.0; 3]; 3], DQuat::IDENTITY, never);
        assert_eq!(w(&s), DMat3::IDENTITY);
        // A mirroring rank-2 matrix: the sign is free, W a rotation, and the recomposition exact.
        let a = [[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.5, 0.0, 2.0]];
        let s = svd(&a, DQuat::IDENTITY, never);
        assert_eq!(s.sign, 1.0);
        assert!(w(&s).determinant() > 0.999_999);
        assert!(recomposed(&s).abs_diff_eq(matrix(&a), 1e-15));
    }
}
