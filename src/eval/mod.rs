//! Pure evaluation: sample a clip at a time into local transforms, layer runtime techniques on it (blends,
//! additive clips, crossfades, procedural shake, targets), then combine them into model matrices with each bone's
//! scale-inheritance mode; skin meshes at the resulting pose.

mod bind;
pub mod blender;
mod chains;
mod cursor;
mod evaluation;
mod hierarchy;
pub mod layers;
mod morph;
mod pose;
mod runs;
mod sample;
mod setup;
pub mod skinning;
mod variant;

pub use bind::{bind_model_matrices, bind_pose, skin_bind_spaces};
pub(crate) use bind::{invert, median};
pub use chains::{BonesEvaluator, Chains};
pub use cursor::BoneCursor;
pub use evaluation::{Evaluation, Evaluator};
pub use hierarchy::{Hierarchy, HierarchyError, ModelPose};
pub use layers::{LayerStack, Layers};
pub use morph::MorphPose;
pub use pose::Pose;
pub use runs::{over_runs, over_runs_from, over_runs_of, run_length};
pub use sample::{Interpolate, sample_clip, sample_track};
pub use setup::{Setup, SetupError};
pub use skinning::{Method as SkinningMethod, Reach, skin_meshes};
#[cfg(test)]
pub(crate) use variant::tests::changes_of as variant_changes_of;
pub use variant::{Beside, Reference, Variant};
