//! Polar decomposition and quaternion helpers on top of glam, in `f64`.

mod polar;
mod quat;
mod svd;

pub use polar::{AffineParts, EQUAL_SCALE_TOLERANCE, decompose, decompose_near, quat_angle, shear_deg};
pub use quat::{nlerp, slerp};
