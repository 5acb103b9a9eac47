//! Polar decomposition and quaternion helpers on top of glam, in `f64`.

mod affine;
mod lanes;
mod polar;
mod quat;
mod rotation;
mod svd;

pub use affine::{affine_inverse, frobenius};
pub use polar::{
    AffineParts, EQUAL_SCALE_TOLERANCE, angle_between, angle_of_half_cosine, decompose, decompose_all, decompose_near,
    decompose_with_stretch, largest_column_cosine, quat_angle, shear_deg, shear_deg_of_cosine,
    stretch_half_cosine_within, stretch_nearest,
};
pub use quat::{Slerp, nlerp, slerp};

/// Property-test inputs shared by the modules' tests.
#[cfg(test)]
pub(crate) mod strategies {
    use glam::DQuat;
    use proptest::prelude::*;

    /// A unit quaternion, from four components away from zero.
    pub fn unit_quat() -> impl Strategy<Value = DQuat> {
        prop::array::uniform4(-1.0..1.0f64)
            .prop_filter("not near zero", |q| q.iter().map(|c| c * c).sum::<f64>() > 1e-3)
            .prop_map(|q| DQuat::from_array(q).normalize())
    }
}
