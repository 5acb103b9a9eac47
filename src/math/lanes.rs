//! Arithmetic on one `f64` or on two side by side in a SIMD register, so that one Jacobi iteration (`svd.rs`)
//! serves a single matrix and a pair of them.
//!
//! A single decomposition is a chain of dependent steps (each rotation waits for the previous one's dot products
//! and division), which leaves most of the processor's arithmetic units idle. Two independent matrices in the two
//! lanes of a register go through the same chain at the same latency, so a batch of matrices costs little more
//! than half as much per matrix.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Sub};

use wide::f64x2;

/// One value per lane, with the operations the Jacobi iteration needs. Comparisons give a [`Lanes::Mask`], one
/// answer per lane.
pub(super) trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask>;

    fn splat(x: f64) -> Self;
    fn abs(self) -> Self;
    fn sqrt(self) -> Self;
    fn max(self, other: Self) -> Self;
    /// `self` with its sign flipped in the lanes where `sign` is negative.
    fn times_sign_of(self, sign: Self) -> Self;
    fn le(self, other: Self) -> Self::Mask;
    fn lt(self, other: Self) -> Self::Mask;
    /// `if_true` in the lanes where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Whether `mask` holds in every lane.
    fn all(mask: Self::Mask) -> bool;
}

impl Lanes for f64 {
    type Mask = bool;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }

    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }

    #[inline(always)]
    fn times_sign_of(self, sign: Self) -> Self {
        self.abs().copysign(self * sign)
    }

    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }

    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }

    #[inline(always)]
    fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
        if mask { if_true } else { if_false }
    }

    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
}

impl Lanes for f64x2 {
    type Mask = f64x2;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        f64x2::splat(x)
    }

    #[inline(always)]
    fn abs(self) -> Self {
        f64x2::abs(self)
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        f64x2::sqrt(self)
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64x2::max(self, other)
    }

    #[inline(always)]
    fn times_sign_of(self, sign: Self) -> Self {
        self ^ (sign & f64x2::splat(-0.0))
    }

    #[inline(always)]
    fn le(self, other: Self) -> f64x2 {
        self.simd_le(other)
    }

    #[inline(always)]
    fn lt(self, other: Self) -> f64x2 {
        self.simd_lt(other)
    }

    #[inline(always)]
    fn select(mask: f64x2, if_true: Self, if_false: Self) -> Self {
        mask.select(if_true, if_false)
    }

    #[inline(always)]
    fn all(mask: f64x2) -> bool {
        mask.all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_kinds_of_lanes_agree() {
        let (a, b) = (f64x2::from([-1.5, 2.0]), f64x2::from([3.0, -0.0]));
        assert_eq!(a.times_sign_of(b).to_array(), [-1.5, -2.0]);
        assert_eq!((-1.5f64).times_sign_of(3.0), -1.5);
        assert_eq!(2.0f64.times_sign_of(-0.0), -2.0);
        let mask = a.le(f64x2::splat(0.0));
        assert_eq!(f64x2::select(mask, a, b).to_array(), [-1.5, -0.0]);
        assert!(!f64x2::all(mask) && f64x2::all(mask | !mask));
        assert!(f64::all(Lanes::le(1.0, 1.0)) && !f64::all(Lanes::le(2.0, 1.0)));
        assert_eq!(<f64x2 as Lanes>::abs(a).to_array(), [1.5, 2.0]);
        assert_eq!(<f64x2 as Lanes>::max(a, b).to_array(), [3.0, 2.0]);
        assert_eq!(<f64x2 as Lanes>::sqrt(f64x2::from([4.0, 9.0])).to_array(), [2.0, 3.0]);
        assert_eq!(f64x2::select(a.lt(b), a, b).to_array(), [-1.5, -0.0]);
        assert!(f64::all(Lanes::lt(1.0, 2.0)) && !f64::all(Lanes::lt(1.0, 1.0)));
    }
}
