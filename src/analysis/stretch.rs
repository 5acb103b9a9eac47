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
        self.0.stretch()
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
pub(crate) struct Stretch {
    /// `V`. The identity when `M` has orthogonal columns (it need not be canonical otherwise).
    pub frame: DQuat,
    /// `K`, all ≥ 0.
    pub scale: DVec3,
    pub sign: f64,
}

impl Stretch {
    /// The stretch of the identity: what a root bone inherits.
    pub const NONE: Stretch = Stretch { frame: DQuat::IDENTITY, scale: DVec3::ONE, sign: 1.0 };

    /// The stretch of a model matrix, decomposed with the search starting from `start`.
    pub fn of_matrix(m: &DMat4, start: DQuat) -> Self {
        let parts = decompose_near(m, start);
        Stretch { frame: parts.stretch, scale: parts.scale, sign: parts.sign }
    }

    /// The stretch of `M·L`, `self` being `M`'s and `L` the local transform read from `local`: a fully inheriting
    /// child (or a root, under [`Stretch::NONE`]). `start` is where a decomposition, when one is needed, starts its
    /// search.
    #[inline]
    pub fn child(&self, local: &mut impl LocalChannels, start: DQuat) -> Self {
        let (scale, own) = (local.scale(), local.stretch());
        if let Some(k) = uniform(self.scale) {
            // M·L = F·k·(W·Vᵀ)·L with W·Vᵀ a rotation: L's own stretch, times k. Negative factors mirror; the
            // stretch keeps their magnitudes (`U·S·Uᵀ = U·|S|·Uᵀ·D` with `D` diagonal ±1 commuting with `|S|`).
            let sign = if scale.x * scale.y * scale.z < 0.0 { -self.sign } else { self.sign };
            return Stretch { frame: own, scale: scale.abs() * k, sign };
        }
        let rotation = local.rotation();
        if own == DQuat::IDENTITY
            && let Some(c) = uniform(scale)
            && c > 0.0
        {
            // K·Vᵀ·R·c = (c·K)·(Rᵀ·V)ᵀ.
            return Stretch { frame: rotation.conjugate() * self.frame, scale: self.scale * c, sign: self.sign };
        }
        let linear = Transform { translation: DVec3::ZERO, rotation, scale, stretch: own }.matrix();
        let parent = DMat3::from_diagonal(self.scale) * DMat3::from_quat(self.frame).transpose();
        let parts = decompose_near(&(affine(parent, DVec3::ZERO) * linear), start);
        Stretch { frame: parts.stretch, scale: parts.scale, sign: self.sign * parts.sign }
    }

    /// Whether it stretches equally in every direction (exactly: the parent of [`Stretch::child`]'s shortcut).
    pub fn is_uniform(&self) -> bool {
        uniform(self.scale).is_some()
    }

    #[inline]
    pub fn verdict(&self, judge: &Judge) -> Verdict {
        judge.verdict(self.frame, self.scale, self.sign, self.shear_cosine_squared())
    }

    /// The square of [`crate::math::largest_column_cosine`] of `M`, from `MᵀM = V·K²·Vᵀ`: `cos²` of columns
    /// `i, j` is `G_ij²/(G_ii·G_jj)`; the largest is found by cross-multiplying, so it takes one division (and no
    /// square root, no column lengths).
    #[inline]
    fn shear_cosine_squared(&self) -> f64 {
        if self.frame == DQuat::IDENTITY || self.is_uniform() {
            return 0.0;
        }
        let v = DMat3::from_quat(self.frame);
        let k2 = self.scale * self.scale;
        // Row i of V, weighted by K², dotted with row j: (V·K²·Vᵀ)_ij.
        let rows = [v.row(0), v.row(1), v.row(2)];
        let gram = |i: usize, j: usize| (rows[i] * k2).dot(rows[j]);
        let diagonal = [gram(0, 0), gram(1, 1), gram(2, 2)];
        let (mut numerator, mut denominator) = (0.0, 1.0);
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            let lengths = diagonal[i] * diagonal[j];
            let dot = gram(i, j);
            if lengths > 0.0 && lengths.is_finite() && dot * dot * denominator > numerator * lengths {
                (numerator, denominator) = (dot * dot, lengths);
            }
        }
        (numerator / denominator).min(1.0)
    }
}

/// The common factor of a vector whose components are exactly equal.
fn uniform(v: DVec3) -> Option<f64> {
    (v.x == v.y && v.y == v.z).then_some(v.x)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::analysis::{Assessment, Tolerances};

    fn quat() -> impl Strategy<Value = DQuat> {
        prop::array::uniform4(-1.0..1.0f64)
            .prop_filter("not near zero", |q| q.iter().map(|c| c * c).sum::<f64>() > 1e-3)
            .prop_map(|q| DQuat::from_array(q).normalize())
    }

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
            let tolerances = Tolerances::default();
            let judge = Judge::new(&tolerances);
            let (mut model, mut stretch) = (DMat4::IDENTITY, Stretch::NONE);
            for (bone, local) in chain.iter().enumerate() {
                model *= local.matrix();
                stretch = stretch.child(&mut &*local, DQuat::IDENTITY);
                let expected = Assessment::of(&model, &tolerances);
                let verdict = stretch.verdict(&judge);
                prop_assert_eq!(verdict.findings, expected.findings, "bone {}", bone);
                prop_assert!((verdict.stretch_deg() - expected.stretch_deg).abs() < 1e-9, "bone {}", bone);
                let shear = crate::math::shear_deg_of_cosine(verdict.shear_cosine_squared.sqrt());
                prop_assert!((shear - expected.shear_deg).abs() < 1e-9, "bone {}: {} vs {}", bone, shear, expected.shear_deg);
                let scale = expected.parts.scale;
                prop_assert!((stretch.scale.max_element() - scale.max_element()).abs() < 1e-12 * scale.max_element());
                prop_assert!((stretch.scale.min_element() - scale.min_element()).abs() < 1e-12 * scale.max_element());
            }
        }
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
        let root = Stretch::NONE.child(&mut Counting(&chain[0], &mut reads), DQuat::IDENTITY);
        let aligned = root.child(&mut Counting(&chain[1], &mut reads), DQuat::IDENTITY);
        assert_eq!(reads, 0, "uniform scale above: no rotation needed");
        assert_eq!(aligned, Stretch { frame: DQuat::IDENTITY, scale: DVec3::new(2.0, 6.0, 2.0), sign: 1.0 });
        let judge = Judge::new(&Tolerances::default());
        assert!(aligned.verdict(&judge).findings.non_uniform);
        // Below the non-uniform bone the child's rotation turns the stretch frame: V = Rᵀ, sheared by 0.7 rad.
        let sheared = aligned.child(&mut Counting(&chain[2], &mut reads), DQuat::IDENTITY);
        assert_eq!(reads, 1);
        assert!(sheared.frame.abs_diff_eq(r.conjugate(), 1e-15));
        assert!(sheared.verdict(&judge).findings.stretched);
    }
}
