//! Every bone's stretch without its model matrix, for whole-clip verdicts.
//!
//! The verdicts on a model matrix `M = F·W·K·Vᵀ` (stretched, non-uniform, mirrored, degenerate, and the shear)
//! depend only on `MᵀM = V·K²·Vᵀ` and the sign `F`, never on the rotation `W`. A fully inheriting child has
//! `M_c = M_p·L`, so `M_cᵀM_c = Lᵀ·(M_pᵀM_p)·L`: the parent's rotation and every translation drop out, and the
//! stretch passes down a chain from local channels alone. The two common cases need no decomposition:
//! - the parent stretches equally in every direction (`K_p = k·I`: only uniform scale above): the child's stretch
//!   is its own local one, times `k`; its rotation is not even read;
//! - the child's own scale is uniform (`c·I`, no local stretch): `V_c = R_cᵀ·V_p`, `K_c = c·K_p`.
//!
//! Only a non-uniformly scaled bone below another one is decomposed (`K_p·V_pᵀ·L`, by SVD). Bones that do not
//! inherit fully are judged from their model matrix.
//!
//! Nor is a bone whose stretch is *certainly* within the anisotropy tolerance of uniform (what every bone of a rig
//! whose scale keys carry single-precision noise, `0.99999994` for 1, is): its verdicts are then known from `MᵀM`
//! alone (not anisotropic, so neither stretched nor non-uniform nor degenerate; the shear from `MᵀM` itself), and it
//! is kept as a matrix `B` with `BᵀB = MᵀM` ([`Stretch::NearlyUniform`]), which passes down like `K_p·V_pᵀ` does.
//! Its children are decomposed only if they leave that bound. The certificate is a bound on the eigenvalues of `MᵀM`
//! ([`Judge::certainly_uniform`]), so the verdicts are those of the decomposition, not an approximation of them.

use glam::{DMat3, DMat4, DQuat, DVec3};

use super::findings::{Judge, Verdict};
use crate::eval::BoneCursor;
use crate::math::decompose_near;
use crate::model::{Transform, affine};

/// A bone's local channels at one time, read on demand.
pub(crate) trait LocalChannels {
    fn rotation(&mut self) -> DQuat;
    fn scale(&mut self) -> DVec3;
    /// The local stretch rotation (the `U` of `T·R·U·S·Uᵀ`).
    fn stretch(&mut self) -> DQuat;
}

/// A bone's channels read from a clip at one time.
pub(crate) struct CursorAt<'c, 'a>(pub &'c mut BoneCursor<'a>, pub f64);

impl LocalChannels for CursorAt<'_, '_> {
    fn rotation(&mut self) -> DQuat {
        self.0.rotation(self.1)
    }

    fn scale(&mut self) -> DVec3 {
        self.0.scale(self.1)
    }

    fn stretch(&mut self) -> DQuat {
        self.0.stretch(self.1)
    }
}

/// A local transform evaluated in full.
impl LocalChannels for &Transform {
    fn rotation(&mut self) -> DQuat {
        self.rotation
    }

    fn scale(&mut self) -> DVec3 {
        self.scale
    }

    fn stretch(&mut self) -> DQuat {
        self.stretch
    }
}

/// The stretch `V·K·Vᵀ` and sign `F` of a model matrix `M = F·W·K·Vᵀ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Stretch {
    /// `V` (`frame`: the identity when `M` has orthogonal columns, not necessarily canonical otherwise), `K`
    /// (`scale`, all ≥ 0) and `F` (`sign`).
    Factored { frame: DQuat, scale: DVec3, sign: f64 },
    /// Certainly within the anisotropy tolerance of uniform ([`Judge::certainly_uniform`]), so never factored: a
    /// matrix `B` with `BᵀB = MᵀM` and a positive determinant, and `F`.
    NearlyUniform { b: DMat3, sign: f64 },
}

impl Stretch {
    /// The stretch of the identity: what a root bone inherits.
    pub const NONE: Stretch = Stretch::Factored { frame: DQuat::IDENTITY, scale: DVec3::ONE, sign: 1.0 };

    /// The stretch of a uniform scale by `factor` (a unit conversion above the roots).
    pub fn uniform(factor: f64) -> Self {
        Stretch::Factored { frame: DQuat::IDENTITY, scale: DVec3::splat(factor), sign: 1.0 }
    }

    /// The stretch of a model matrix, decomposed with the search starting from `start`.
    pub fn of_matrix(m: &DMat4, start: DQuat) -> Self {
        let parts = decompose_near(m, start);
        Stretch::Factored { frame: parts.stretch, scale: parts.scale, sign: parts.sign }
    }

    /// `V`, `K` and `F`, unless it is [`Stretch::NearlyUniform`].
    pub fn factors(&self) -> Option<(DQuat, DVec3, f64)> {
        match *self {
            Stretch::Factored { frame, scale, sign } => Some((frame, scale, sign)),
            Stretch::NearlyUniform { .. } => None,
        }
    }

    /// Where the decomposition of a similar matrix (the same bone at the next sample) best starts.
    pub fn frame(&self) -> DQuat {
        self.factors().map_or(DQuat::IDENTITY, |(frame, _, _)| frame)
    }

    /// The stretch of `M·L`, `self` being `M`'s and `L` the local transform read from `local`: a fully inheriting
    /// child (or a root, under [`Stretch::NONE`]). `start` is where a decomposition, when one is needed, starts its
    /// search; none is when `judge` can certify the result nearly uniform.
    #[inline]
    pub fn child(&self, local: &mut impl LocalChannels, start: DQuat, judge: &Judge) -> Self {
        let (scale, own) = (local.scale(), local.stretch());
        let (parent, sign, factors) = match *self {
            Stretch::Factored { frame, scale: k, sign } => {
                if let Some(k) = uniform(k) {
                    // M·L = F·k·(W·Vᵀ)·L with W·Vᵀ a rotation: L's own stretch, times k. Negative factors mirror;
                    // the stretch keeps their magnitudes (`U·S·Uᵀ = U·|S|·Uᵀ·D` with `D` diagonal ±1 commuting
                    // with `|S|`).
                    let sign = if scale.x * scale.y * scale.z < 0.0 { -sign } else { sign };
                    return Stretch::Factored { frame: own, scale: scale.abs() * k, sign };
                }
                (DMat3::from_diagonal(k) * DMat3::from_quat(frame).transpose(), sign, Some((frame, k)))
            }
            Stretch::NearlyUniform { b, sign } => (b, sign, None),
        };
        let rotation = local.rotation();
        if let Some((frame, k)) = factors
            && own == DQuat::IDENTITY
            && let Some(c) = uniform(scale)
            && c > 0.0
        {
            // K·Vᵀ·R·c = (c·K)·(Rᵀ·V)ᵀ.
            return Stretch::Factored { frame: rotation.conjugate() * frame, scale: k * c, sign };
        }
        let linear = DMat3::from_mat4(Transform { translation: DVec3::ZERO, rotation, scale, stretch: own }.matrix());
        let a = parent * linear;
        if judge.certainly_uniform(&(a.transpose() * a)) {
            // A certified matrix is far from singular: its determinant's sign is reliable.
            let mirrored = a.determinant() < 0.0;
            let b = if mirrored { -a } else { a };
            return Stretch::NearlyUniform { b, sign: if mirrored { -sign } else { sign } };
        }
        let parts = decompose_near(&affine(a, DVec3::ZERO), start);
        Stretch::Factored { frame: parts.stretch, scale: parts.scale, sign: sign * parts.sign }
    }

    /// Whether it stretches equally in every direction (exactly: the parent of [`Stretch::child`]'s shortcut).
    pub fn is_uniform(&self) -> bool {
        matches!(*self, Stretch::Factored { scale, .. } if uniform(scale).is_some())
    }

    #[inline]
    pub fn verdict(&self, judge: &Judge) -> Verdict {
        match *self {
            Stretch::Factored { frame, scale, sign } => {
                let shear = if frame == DQuat::IDENTITY || uniform(scale).is_some() {
                    0.0
                } else {
                    let v = DMat3::from_quat(frame);
                    largest_cosine_squared(&(v * DMat3::from_diagonal(scale * scale) * v.transpose()))
                };
                judge.verdict(frame, scale, sign, shear)
            }
            Stretch::NearlyUniform { b, sign } => {
                judge.uniform_verdict(sign, largest_cosine_squared(&(b.transpose() * b)))
            }
        }
    }
}

/// The square of [`crate::math::largest_column_cosine`] of `M`, from its Gram matrix `MᵀM` (`V·K²·Vᵀ`): `cos²` of
/// columns `i, j` is `G_ij²/(G_ii·G_jj)`; the largest is found by cross-multiplying, so it takes one division (and no
/// square root, no column lengths).
#[inline]
fn largest_cosine_squared(gram: &DMat3) -> f64 {
    let g = |i: usize, j: usize| gram.col(j)[i];
    let diagonal = [g(0, 0), g(1, 1), g(2, 2)];
    let (mut numerator, mut denominator) = (0.0, 1.0);
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let lengths = diagonal[i] * diagonal[j];
        let dot = g(i, j);
        if lengths > 0.0 && lengths.is_finite() && dot * dot * denominator > numerator * lengths {
            (numerator, denominator) = (dot * dot, lengths);
        }
    }
    (numerator / denominator).min(1.0)
}

fn uniform(v: DVec3) -> Option<f64> {
    (v.x == v.y && v.y == v.z).then_some(v.x)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::analysis::{Assessment, Tolerances};
    use crate::math::strategies::unit_quat as quat;

    /// A local scale: uniform, non-uniform, with a negative factor, or the identity (each case has its path).
    fn scale() -> impl Strategy<Value = DVec3> {
        prop_oneof![
            Just(DVec3::ONE),
            (0.2..3.0f64).prop_map(DVec3::splat),
            prop::array::uniform3(0.2..3.0f64).prop_map(DVec3::from_array),
            prop::array::uniform3(0.2..3.0f64).prop_map(|s| DVec3::new(-s[0], s[1], s[2])),
        ]
    }

    fn transform() -> impl Strategy<Value = Transform> {
        let stretch = prop_oneof![3 => Just(DQuat::IDENTITY), 1 => quat()];
        (prop::array::uniform3(-2.0..2.0f64), quat(), scale(), stretch).prop_map(|(t, rotation, scale, stretch)| {
            Transform { translation: DVec3::from_array(t), rotation, scale, stretch }
        })
    }

    proptest! {
        /// Down a chain of fully inheriting bones, the propagated stretch gives the verdicts, the stretch angle
        /// and the shear of the decomposed model matrix (to 1e-9 degrees; exactly for the verdicts, whose inputs
        /// here stay away from the tolerances).
        #[test]
        fn the_propagated_stretch_judges_as_the_model_matrix(chain in prop::collection::vec(transform(), 1..7)) {
            prop_assert_eq!(judges_as_the_model_matrix(&chain, &Tolerances::default()), Ok(()));
        }

        /// The same for chains whose scales carry single-precision noise (`1 ± 2⁻²³`), nearly uniform bones
        /// judged without decomposing them, and a non-uniform bone below them.
        #[test]
        fn nearly_uniform_chains_judge_as_the_model_matrix(
            chain in prop::collection::vec((quat(), prop::array::uniform3(-4i32..=4)), 1..7),
            last in transform(),
        ) {
            let noisy = |(rotation, steps): &(DQuat, [i32; 3])| {
                let scale = DVec3::from_array(steps.map(|s| 1.0 + f64::from(s) * f64::from(f32::EPSILON)));
                Transform::from_trs(DVec3::X, *rotation, scale)
            };
            let mut chain: Vec<Transform> = chain.iter().map(noisy).collect();
            chain.push(last);
            prop_assert_eq!(judges_as_the_model_matrix(&chain, &Tolerances::default()), Ok(()));
        }
    }

    /// Down a chain, whether the propagated stretch judges every bone as its decomposed model matrix does: the
    /// verdicts exactly (inputs away from the tolerances), the stretch angle and shear to 1e-9 degrees (the angle
    /// to what its inverse cosine allows, for angles within a few millionths of a degree of none), the scale
    /// factors to 1e-12 where the stretch is factored.
    fn judges_as_the_model_matrix(chain: &[Transform], tolerances: &Tolerances) -> Result<(), String> {
        let judge = Judge::new(tolerances);
        let (mut model, mut stretch) = (DMat4::IDENTITY, Stretch::NONE);
        for (bone, local) in chain.iter().enumerate() {
            model *= local.matrix();
            stretch = stretch.child(&mut &*local, DQuat::IDENTITY, &judge);
            let expected = Assessment::of(&model, tolerances);
            let verdict = stretch.verdict(&judge);
            let shear = crate::math::shear_deg_of_cosine(verdict.shear_cosine_squared.sqrt());
            let factors_agree = stretch.factors().is_none_or(|(_, scale, _)| {
                let expected = expected.parts.scale;
                (scale.max_element() - expected.max_element()).abs() < 1e-12 * expected.max_element()
                    && (scale.min_element() - expected.min_element()).abs() < 1e-12 * expected.max_element()
            });
            // A stretch angle read back from its half-angle cosine loses what the inverse cosine loses near 1:
            // a few units of the last place of the cosine, over the sine of the half angle.
            let half = (0.5 * expected.stretch_deg.to_radians()).sin().max(f64::EPSILON);
            let acos_loss = (2.0 * 4.0 * f64::EPSILON / half).to_degrees();
            if verdict.findings != expected.findings
                || (verdict.stretch_deg() - expected.stretch_deg).abs() >= 1e-9 + acos_loss
                || (shear - expected.shear_deg).abs() >= 1e-9
                || !factors_agree
            {
                return Err(format!("bone {bone}: {stretch:?} gives {verdict:?}, the model matrix {expected:?}"));
            }
        }
        Ok(())
    }

    #[test]
    fn noisy_unit_scales_are_certified_uniform_unless_the_tolerance_is_tighter() {
        let noisy = Transform::from_trs(DVec3::X, DQuat::from_rotation_x(0.4), DVec3::new(1.0, 1.0 + 1e-7, 1.0 - 1e-7));
        let chain = [noisy, noisy, noisy];
        let child = |tolerances: &Tolerances| {
            let judge = Judge::new(tolerances);
            chain.iter().fold(Stretch::NONE, |above, local| above.child(&mut &*local, DQuat::IDENTITY, &judge))
        };
        assert!(matches!(child(&Tolerances::default()), Stretch::NearlyUniform { .. }));
        let tight = Tolerances { min_anisotropy: 1e-8, ..Tolerances::default() };
        assert!(matches!(child(&tight), Stretch::Factored { .. }), "3e-7 of anisotropy is not within 1e-8");
        let zero = Tolerances { min_anisotropy: 0.0, ..Tolerances::default() };
        assert!(matches!(child(&zero), Stretch::Factored { .. }), "nothing is certified without a tolerance");
    }

    #[test]
    fn a_root_under_none_and_a_uniform_chain_read_no_rotation() {
        struct Counting<'a>(&'a Transform, &'a mut usize);
        impl LocalChannels for Counting<'_> {
            fn rotation(&mut self) -> DQuat {
                *self.1 += 1;
                self.0.rotation
            }
            fn scale(&mut self) -> DVec3 {
                self.0.scale
            }
            fn stretch(&mut self) -> DQuat {
                self.0.stretch
            }
        }
        let r = DQuat::from_rotation_z(0.7);
        let chain = [
            Transform::from_trs(DVec3::X, r, DVec3::splat(2.0)),
            Transform::from_trs(DVec3::Y, r, DVec3::new(1.0, 3.0, 1.0)),
            Transform::from_trs(DVec3::Y, r, DVec3::ONE),
        ];
        let mut reads = 0;
        let judge = Judge::new(&Tolerances::default());
        let root = Stretch::NONE.child(&mut Counting(&chain[0], &mut reads), DQuat::IDENTITY, &judge);
        let aligned = root.child(&mut Counting(&chain[1], &mut reads), DQuat::IDENTITY, &judge);
        assert_eq!(reads, 0, "uniform scale above: no rotation needed");
        assert_eq!(aligned, Stretch::Factored { frame: DQuat::IDENTITY, scale: DVec3::new(2.0, 6.0, 2.0), sign: 1.0 });
        assert!(aligned.verdict(&judge).findings.non_uniform);
        // Below the non-uniform bone the child's rotation turns the stretch frame: V = Rᵀ, sheared by 0.7 rad.
        let sheared = aligned.child(&mut Counting(&chain[2], &mut reads), DQuat::IDENTITY, &judge);
        assert_eq!(reads, 1);
        assert!(sheared.frame().abs_diff_eq(r.conjugate(), 1e-15));
        assert!(sheared.verdict(&judge).findings.stretched);
    }
}
