//! The loaded document: skeleton, clips, skins and meshes, independent of the file format they came from.

mod choice;
mod clip;
mod inherit;
mod skeleton;
mod skin;
mod timeline;
mod transform;

pub use choice::Choice;
pub use clip::{
    BoneTracks, Clip, DEFAULT_FRAME_RATE, Interpolation, KEY_TIME_RESOLUTION, KeyValue, MorphWeights, Track, TrackError,
};
pub use inherit::{InheritMode, ModeChoice, UnknownInheritMode, UnknownModeChoice};
#[cfg(test)]
pub(crate) use skeleton::named as named_skeleton;
pub use skeleton::{Bone, NodeRole, ParentOrderError, Skeleton};
pub use skin::{Mesh, MorphTarget, NodeBind, Skin, WEIGHT_SUM_TOLERANCE, normalized_weights};
pub use timeline::{MAX_FRAMES, SAMPLES_PER_SPARSE_GAP, SampleTimes, sample_times};
pub use transform::{Transform, affine};

/// Everything bonescope knows about one file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rig {
    pub skeleton: Skeleton,
    pub clips: Vec<Clip>,
    pub skins: Vec<Skin>,
    pub meshes: Vec<Mesh>,
    /// Facts about the import a user should know (units, axes, what was listed but not evaluated).
    pub notes: Vec<String>,
}

impl Rig {
    /// The clip named `name`, or with index `name` when it parses as a number.
    pub fn find_clip(&self, name: &str) -> Option<&Clip> {
        self.clips
            .iter()
            .find(|c| c.name.as_deref() == Some(name))
            .or_else(|| name.parse::<usize>().ok().and_then(|i| self.clips.get(i)))
    }
}
