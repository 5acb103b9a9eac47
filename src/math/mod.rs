//! Polar decomposition and quaternion helpers on top of glam, in `f64`.

mod lanes;
mod polar;
mod quat;
mod rotation;
mod svd;

pub use polar::{
    AffineParts, EQUAL_SCALE_TOLERANCE, angle_between, angle_of_half_cosine, decompose, decompose_all, decompose_near,
    decompose_with_stretch, largest_column_cosine, quat_angle, shear_deg, shear_deg_of_cosine,
    stretch_half_cosine_within, stretch_nearest,
};
pub use quat::{Slerp, nlerp, slerp};
