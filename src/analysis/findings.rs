//! What is wrong with one matrix: stretched (sheared), non-uniformly scaled, mirrored, degenerate.

use glam::{DMat3, DMat4, DQuat, DVec3};

use crate::math::{
    AffineParts, angle_of_half_cosine, decompose_all, decompose_near, largest_column_cosine, shear_deg_of_cosine,
    stretch_half_cosine_within,
};

/// The tolerances behind the verdicts.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Tolerances {
    /// Scale factors count as unequal in judging a stretch when `max/min − 1` exceeds this (default 1e-4, i.e.
    /// 0.01 %).
    pub min_anisotropy: f64,
    /// A stretch rotation counts as not the identity when its angle exceeds this many degrees (default 0.01°).
    pub min_stretch_deg: f64,
    /// A stretched bone is flagged only when it shears by more than this many degrees (default 0.01°): at the first
    /// frames of a squash a stretch frame may turn while the shear it makes is numerically invisible.
    pub min_shear_deg: f64,
    /// A matrix is degenerate when its smallest scale factor is below this fraction of its largest (default 1e-9).
    pub degenerate_ratio: f64,
    /// A bone not stretched is non-uniformly scaled when `max/min − 1` of its scale factors exceeds this (default
    /// 1e-3, i.e. 0.1 %): exporters leave factors of 1 apart by rounding (a Mixamo leg at (0.99989, 1.0000001,
    /// 0.99998)), which no one reads as a scale. The stretched verdict keeps `min_anisotropy`.
    pub min_non_uniform: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            min_anisotropy: 1e-4,
            min_stretch_deg: 0.01,
            min_shear_deg: 0.01,
            degenerate_ratio: 1e-9,
            min_non_uniform: 1e-3,
        }
    }
}

/// The colour a stretched bone is drawn in, sRGB: its shear on a ramp from pale (0.1° and below, barely visible) to
/// the full colour (10° and more), logarithmic between, mixed byte by byte. The same in the app and the reports.
pub fn shear_rgb(shear_deg: f64) -> [u8; 3] {
    const PALE: [u8; 3] = [250, 200, 210];
    let t = ((shear_deg.max(1e-12).log10() + 1.0) / 2.0).clamp(0.0, 1.0);
    std::array::from_fn(|i| (f64::from(PALE[i]) + t * (f64::from(STRETCHED_RGB[i]) - f64::from(PALE[i]))).round() as u8)
}

/// The colour of a stretched bone, sRGB.
pub const STRETCHED_RGB: [u8; 3] = [235, 64, 100];

/// The verdicts on one matrix. `stretched` and `non_uniform` exclude each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Findings {
    /// Unequal scale along axes that are not the bone's own (`U ≠ I`): shear a TRS runtime cannot represent.
    pub stretched: bool,
    /// Unequal scale along the bone's own axes: representable as TRS.
    pub non_uniform: bool,
    /// Negative determinant.
    pub mirrored: bool,
    /// A (nearly) zero scale factor: the bone collapses a direction.
    pub degenerate: bool,
}

impl Findings {
    pub fn any(&self) -> bool {
        self.stretched || self.non_uniform || self.mirrored || self.degenerate
    }
}

/// A matrix decomposed and judged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Assessment {
    pub parts: AffineParts,
    /// Largest deviation from 90° between two columns, in degrees.
    pub shear_deg: f64,
    /// The angle of the stretch rotation with scale factors within `min_anisotropy` of each other merged
    /// ([`AffineParts::stretch_angle_deg_within`]), in degrees.
    pub stretch_deg: f64,
    pub findings: Findings,
}

impl Assessment {
    pub fn of(m: &DMat4, tolerances: &Tolerances) -> Self {
        Self::near(m, tolerances, DQuat::IDENTITY)
    }

    /// [`Assessment::of`], the decomposition searching from `start` (see [`decompose_near`]): the same bone's
    /// stretch frame at the previous sample makes a whole-clip scan faster.
    pub fn near(m: &DMat4, tolerances: &Tolerances, start: DQuat) -> Self {
        Self::judged(m, decompose_near(m, start), &Judge::new(tolerances))
    }

    /// [`Assessment::of`] every matrix (a whole pose), decomposed together ([`decompose_all`]: less time per
    /// matrix).
    pub fn all(ms: &[DMat4], tolerances: &Tolerances) -> Vec<Self> {
        let judge = Judge::new(tolerances);
        decompose_all(ms).into_iter().zip(ms).map(|(parts, m)| Self::judged(m, parts, &judge)).collect()
    }

    /// `m`, decomposed into `parts`, judged.
    fn judged(m: &DMat4, parts: AffineParts, judge: &Judge) -> Self {
        let cosine = shear_cosine(&parts, m);
        let verdict = judge.verdict(parts.stretch, parts.scale, parts.sign, cosine * cosine);
        Assessment {
            parts,
            shear_deg: shear_deg_of_cosine(cosine),
            stretch_deg: verdict.stretch_deg(),
            findings: verdict.findings,
        }
    }
}

/// [`largest_column_cosine`] of `m` decomposed into `parts`: an identity stretch means `M = F·R·K`, orthogonal
/// columns, so the shear is zero without measuring it.
pub(crate) fn shear_cosine(parts: &AffineParts, m: &DMat4) -> f64 {
    if parts.stretch == DQuat::IDENTITY { 0.0 } else { largest_column_cosine(&DMat3::from_mat4(*m)) }
}

/// How far apart, relatively, the tolerances of [`clearly_stretched`]'s two judges lie: far beyond what rounding moves
/// a decomposition by (1e-12 and less: any start, any order of products), far within what a tolerance means.
const CLEAR: f64 = 1e-6;

/// Whether `m` is stretched, where rounding cannot change that: the verdict under tolerances [`CLEAR`] tighter and
/// under tolerances as much looser agree (each tolerance only ever clears a matrix that a tighter one flags, so
/// every tolerance between them agrees too), so that any other decomposition of `m`, from any start or through the
/// products it is evaluated by, judges it the same. `None` near a tolerance, and where a tolerance leaves no room
/// for rounding (too small to tell a uniform scale from its rounding).
pub(crate) fn clearly_stretched(m: &DMat4, tolerances: &Tolerances) -> Option<bool> {
    let roomy = tolerances.min_anisotropy >= CERTIFIABLE_ANISOTROPY
        && tolerances.min_stretch_deg > 0.0
        && tolerances.min_shear_deg > 0.0;
    if !roomy {
        return None;
    }
    let parts = decompose_near(m, DQuat::IDENTITY);
    let cosine = shear_cosine(&parts, m);
    let stretched = |factor: f64| {
        let scaled = Tolerances {
            min_anisotropy: tolerances.min_anisotropy * factor,
            min_stretch_deg: tolerances.min_stretch_deg * factor,
            min_shear_deg: tolerances.min_shear_deg * factor,
            ..*tolerances
        };
        Judge::new(&scaled).verdict(parts.stretch, parts.scale, parts.sign, cosine * cosine).findings.stretched
    };
    let (tighter, looser) = (stretched(1.0 - CLEAR), stretched(1.0 + CLEAR));
    (tighter == looser).then_some(looser)
}

/// The tolerances prepared for judging many matrices.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Judge {
    tolerances: Tolerances,
    /// `cos(θ/2)` at `θ = min_stretch_deg`: stretch frames turned further have a smaller half-angle cosine.
    stretch_half_cosine: f64,
    /// `sin²(min_shear_deg)`: a shear of angle `φ` has a largest column cosine of `sin φ`.
    shear_cosine_squared: f64,
    /// The square of the largest spread `e/g` of `MᵀM` around `g·I` ([`Judge::certainly_uniform`]) that keeps the
    /// scale factors' ratio below 1 + half the smaller of `min_anisotropy` and `min_non_uniform`; 0 where the
    /// tolerances leave no room for that.
    uniform_spread_squared: f64,
}

/// Anisotropy tolerances below this are too close to rounding for [`Judge::certainly_uniform`] to certify anything.
const CERTIFIABLE_ANISOTROPY: f64 = 1e-10;

impl Judge {
    pub fn new(tolerances: &Tolerances) -> Self {
        let stretch_half_cosine = (tolerances.min_stretch_deg.to_radians() * 0.5).cos();
        let shear_cosine_squared = tolerances.min_shear_deg.to_radians().sin().powi(2);
        // Eigenvalues of MᵀM within g·(1 ± s) put the factors' ratio at most √((1+s)/(1−s)); half the tolerance is
        // the target, the other half the margin for rounding (some 1e-15 here, in the SVD's factors).
        let anisotropy = tolerances.min_anisotropy.min(tolerances.min_non_uniform);
        let ratio_squared = (1.0 + 0.5 * anisotropy).powi(2);
        let spread = (ratio_squared - 1.0) / (ratio_squared + 1.0);
        let certifiable =
            anisotropy >= CERTIFIABLE_ANISOTROPY && tolerances.degenerate_ratio * (1.0 + anisotropy) < 1.0;
        let uniform_spread_squared = if certifiable { spread * spread } else { 0.0 };
        Judge { tolerances: *tolerances, stretch_half_cosine, shear_cosine_squared, uniform_spread_squared }
    }

    /// Whether a shear whose largest column cosine is the square root of `shear_cosine_squared` passes the shear
    /// tolerance.
    pub fn sees_shear(&self, shear_cosine_squared: f64) -> bool {
        shear_cosine_squared > self.shear_cosine_squared
    }

    /// Whether a matrix with the Gram matrix `gram` (`MᵀM`) certainly has scale factors within half the smaller
    /// anisotropy tolerance (`min_anisotropy`, `min_non_uniform`) of each other: every eigenvalue of `MᵀM` lies
    /// within `‖MᵀM − g·I‖_F` of `g`, its mean. Its verdicts are then [`Judge::uniform_verdict`]'s, whatever its
    /// stretch frame.
    #[inline]
    pub fn certainly_uniform(&self, gram: &DMat3) -> bool {
        let g = (gram.x_axis.x + gram.y_axis.y + gram.z_axis.z) / 3.0;
        let spread = *gram - DMat3::from_diagonal(DVec3::splat(g));
        let squared = spread.x_axis.length_squared() + spread.y_axis.length_squared() + spread.z_axis.length_squared();
        // Strictly below: nothing passes when the tolerances leave no room (a spread of 0).
        g > 0.0 && squared < self.uniform_spread_squared * g * g
    }

    /// The verdicts on a matrix [`Judge::certainly_uniform`] passed, of determinant sign `sign`: not anisotropic, so
    /// neither stretched nor non-uniform (the stretch angle is 0), nor degenerate.
    pub fn uniform_verdict(&self, sign: f64, shear_cosine_squared: f64) -> Verdict {
        let findings = Findings { stretched: false, non_uniform: false, mirrored: sign < 0.0, degenerate: false };
        Verdict { findings, stretch_half_cosine: 1.0, shear_cosine_squared }
    }

    /// The verdicts on a matrix whose stretch is `U·K·Uᵀ` (`U = R(stretch)`, `K = diag(scale)`), whose
    /// determinant has the sign `sign` (all they depend on) and whose [`largest_column_cosine`] is the square root
    /// of `shear_cosine_squared`.
    #[inline]
    pub fn verdict(&self, stretch: DQuat, scale: DVec3, sign: f64, shear_cosine_squared: f64) -> Verdict {
        let tolerances = &self.tolerances;
        let (min, max) = (scale.min_element(), scale.max_element());
        // `max/min − 1 > tolerance` (`AffineParts::anisotropy`), without the division.
        let beyond = |tolerance: f64| max > min * (1.0 + tolerance);
        let anisotropic = beyond(tolerances.min_anisotropy);
        let stretch_half_cosine =
            if anisotropic { stretch_half_cosine_within(stretch, scale, tolerances.min_anisotropy) } else { 1.0 };
        let stretched =
            stretch_half_cosine < self.stretch_half_cosine && shear_cosine_squared > self.shear_cosine_squared;
        let findings = Findings {
            stretched,
            non_uniform: beyond(tolerances.min_non_uniform) && !stretched,
            mirrored: sign < 0.0,
            degenerate: min <= tolerances.degenerate_ratio * max,
        };
        Verdict { findings, stretch_half_cosine, shear_cosine_squared }
    }
}

/// One matrix's verdicts and the measures behind them, in the form a whole-clip summary compares them: cosines,
/// whose inverse is taken only for a new worst.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Verdict {
    pub findings: Findings,
    /// `cos(θ/2)` of the stretch angle `θ` ([`Assessment::stretch_deg`]).
    pub stretch_half_cosine: f64,
    /// The shear as the square of [`largest_column_cosine`].
    pub shear_cosine_squared: f64,
}

impl Verdict {
    /// See [`Assessment::stretch_deg`].
    pub fn stretch_deg(&self) -> f64 {
        angle_of_half_cosine(self.stretch_half_cosine)
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;

    fn assess(m: DMat4) -> Findings {
        Assessment::of(&m, &Tolerances::default()).findings
    }

    #[test]
    fn verdicts() {
        let r = DQuat::from_rotation_y(0.8);
        let aligned = DMat4::from_scale_rotation_translation(DVec3::new(2.0, 1.0, 1.0), r, DVec3::ZERO);
        assert_eq!(assess(aligned), Findings { non_uniform: true, ..Findings::default() });
        let sheared =
            DMat4::from_cols(glam::DVec4::X, glam::DVec4::new(0.5, 1.0, 0.0, 0.0), glam::DVec4::Z, glam::DVec4::W);
        assert_eq!(assess(sheared), Findings { stretched: true, ..Findings::default() });
        let mirrored = DMat4::from_scale(DVec3::new(1.0, -1.0, 1.0));
        assert_eq!(assess(mirrored), Findings { mirrored: true, ..Findings::default() });
        assert!(assess(DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0))).degenerate);
        assert!(assess(DMat4::ZERO).degenerate);
        assert!(!assess(DMat4::from_quat(r)).any());
        // Within tolerance: 0.001 % anisotropy is not reported.
        assert!(!assess(DMat4::from_scale(DVec3::new(1.0, 1.00001, 1.0))).any());
        // Two factors 1e-6 apart and a third distinct, the nearly equal pair turned 30° in its plane: the turn
        // changes the matrix by about 1e-6 only, so the bone is aligned, not stretched.
        let twisted = DMat4::from_quat(DQuat::from_rotation_z(0.5))
            * DMat4::from_scale(DVec3::new(1.0, 1.000001, 0.5))
            * DMat4::from_quat(DQuat::from_rotation_z(-0.5));
        assert_eq!(assess(twisted), Findings { non_uniform: true, ..Findings::default() });
    }

    #[test]
    fn shear_below_the_minimum_angle_is_not_flagged() {
        // A unit shear of tan φ: φ = 0.005° is below the default 0.01°, φ = 0.02° above it.
        let shear = |deg: f64| {
            let t = deg.to_radians().tan();
            DMat4::from_cols(glam::DVec4::X, glam::DVec4::new(t, 1.0, 0.0, 0.0), glam::DVec4::Z, glam::DVec4::W)
        };
        let tolerances =
            Tolerances { min_anisotropy: 0.0, min_stretch_deg: 0.0, min_non_uniform: 0.0, ..Tolerances::default() };
        let assess = |m: DMat4| Assessment::of(&m, &tolerances);
        let faint = assess(shear(0.005));
        assert!(!faint.findings.stretched && faint.findings.non_uniform, "{faint:?}");
        assert!(assess(shear(0.02)).findings.stretched);
        let lenient = Tolerances { min_shear_deg: 0.0, ..tolerances };
        assert!(Assessment::of(&shear(0.005), &lenient).findings.stretched);
    }
    /// A squash `(k, 1, 1)` seen from a child turned 45° about Z: a shear of `asin((k² − 1)/(k² + 1))`.
    fn squash_turned(k: f64) -> DMat4 {
        let turn = DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4));
        DMat4::from_scale(DVec3::new(k, 1.0, 1.0)) * turn
    }

    /// The squash whose shear is `deg` degrees.
    fn squash_shearing(deg: f64) -> DMat4 {
        let sine = deg.to_radians().sin();
        squash_turned(((1.0 + sine) / (1.0 - sine)).sqrt())
    }

    #[test]
    fn a_verdict_is_clear_away_from_every_tolerance() {
        let tolerances = Tolerances::default();
        assert_eq!(clearly_stretched(&squash_turned(1.5), &tolerances), Some(true));
        assert_eq!(clearly_stretched(&DMat4::from_quat(DQuat::from_rotation_y(0.8)), &tolerances), Some(false));
        assert_eq!(clearly_stretched(&DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0)), &tolerances), Some(false));
        // The shear a billionth of itself past the shear tolerance: flagged, but not clearly.
        let edge = squash_shearing(0.01 * (1.0 + 1e-9));
        assert!(Assessment::of(&edge, &tolerances).findings.stretched);
        assert_eq!(clearly_stretched(&edge, &tolerances), None);
        assert_eq!(clearly_stretched(&squash_shearing(0.01 * (1.0 + 1e-4)), &tolerances), Some(true));
        // No tolerance, no margin: a uniform scale and its rounding could be told apart.
        let none = Tolerances { min_anisotropy: 0.0, ..tolerances };
        assert_eq!(clearly_stretched(&squash_turned(1.5), &none), None);
    }

    proptest::proptest! {
        /// Where one decomposition clearly judges a matrix, a decomposition from any start judges it so.
        #[test]
        fn a_clear_verdict_is_every_decomposition_s(
            k in 1.0..1.001f64,
            turn in proptest::array::uniform4(-1.0..1.0f64),
            start in proptest::array::uniform4(-1.0..1.0f64),
        ) {
            let unit = |q: [f64; 4]| {
                let q = DQuat::from_array(q);
                if q.length() > 1e-3 { q.normalize() } else { DQuat::IDENTITY }
            };
            let m = DMat4::from_scale(DVec3::new(k, 1.0, 1.0)) * DMat4::from_quat(unit(turn));
            let tolerances = Tolerances::default();
            if let Some(clear) = clearly_stretched(&m, &tolerances) {
                proptest::prop_assert_eq!(Assessment::near(&m, &tolerances, unit(start)).findings.stretched, clear);
            }
        }
    }
}
