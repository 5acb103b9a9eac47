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
pub use skeleton::{Bone, ParentOrderError, Skeleton};
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

    /// For each bone, whether it belongs to the character: the bones `clip` animates and the skins' joints, so that a
    /// file's cameras, lights and helpers far from it (FBX exports often carry six "Producer" cameras 150 m out)
    /// stay out of its size and framing; every bone when that leaves none.
    pub fn character_bones(&self, clip: Option<&Clip>) -> Vec<bool> {
        let mut character = vec![false; self.skeleton.len()];
        let animated = clip.into_iter().flat_map(|c| c.tracks().iter().map(|t| t.bone));
        let joints = self.skins.iter().flat_map(|s| s.joints.iter().copied());
        for bone in animated.chain(joints) {
            if let Some(c) = character.get_mut(bone) {
                *c = true;
            }
        }
        if !character.contains(&true) {
            character.fill(true);
        }
        character
    }
}
