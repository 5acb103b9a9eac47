//! Pure evaluation: sample a clip at a time into local transforms, then combine them into model matrices with
//! each bone's scale-inheritance mode; skin meshes at the resulting pose.

pub mod blender;
mod hierarchy;
mod pose;
mod sample;
pub mod skinning;

pub use hierarchy::{Hierarchy, ModelPose};
pub use pose::Pose;
pub use sample::{Interpolate, sample_clip, sample_track};
pub use skinning::skin_meshes;
