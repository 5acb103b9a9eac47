//! The loaded document: skeleton, clips, skins and meshes, independent of the file format they came from.

mod axes;
mod choice;
mod clip;
mod inherit;
mod skeleton;
mod skin;
mod timeline;
mod tool;
mod transform;
mod unit;

pub use axes::UpAxis;
pub use choice::Choice;
pub use clip::{
    BoneTracks, Clip, DEFAULT_FRAME_RATE, Interpolation, KEY_TIME_RESOLUTION, KeyValue, MorphWeights, Track, TrackError,
};
pub use inherit::{InheritMode, ModeChoice, Modes, UnknownInheritMode, UnknownModeChoice};
#[cfg(test)]
pub(crate) use skeleton::named as named_skeleton;
pub use skeleton::{Bone, NodeRole, ParentOrderError, Placement, Skeleton};
pub use skin::{Mesh, MorphTarget, NodeBind, Skin, WEIGHT_SUM_TOLERANCE, normalized_weights};
pub use timeline::{At, MAX_FRAMES, SAMPLES_PER_SPARSE_GAP, SampleTimes, Span, frames, sample_times, with_midpoints};
pub use tool::Tool;
pub use transform::{Transform, affine};
pub(crate) use unit::significant;
pub use unit::{Unit, UnknownUnit};

/// How a rig's notes say the up axis it was given.
const UP_NOTE: &str = "axes: given as up along ";

/// How a rig's notes start that name meshes of the file left out, and why (their data not in the file, their
/// compression not decoding): what the app says on opening the file, beside `inspect`'s every note.
pub const NOT_DRAWN_NOTE: &str = "not drawn, ";

/// Everything bonescope knows about one file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rig {
    pub skeleton: Skeleton,
    pub clips: Vec<Clip>,
    pub skins: Vec<Skin>,
    pub meshes: Vec<Mesh>,
    /// What its lengths are in, `None` where the file does not say (BVH): every reader fills it, and comparisons
    /// bring two rigs into one unit with it.
    pub unit: Option<Unit>,
    /// Facts about the import a user should know (units, axes, what was listed but not evaluated).
    pub notes: Vec<String>,
    /// The tool that wrote the file, where the file says and the tool has scale-inheritance settings of its own.
    pub tool: Option<Tool>,
}

impl Rig {
    /// The clip a viewer opens on: the one that keys the most channels, the first of those that key as many; `None`
    /// without clips. facecap's eyes-only clip is not opened on beside its face's, nor a Mixamo FBX's empty
    /// `Take 001` beside its `mixamo.com`.
    pub fn opening_clip(&self) -> Option<usize> {
        // `max_by_key` takes the last of equals: from the end, that is the first.
        self.clips.iter().enumerate().rev().max_by_key(|(_, clip)| clip.channels()).map(|(i, _)| i)
    }

    /// The clip named `name`, or with index `name` when it parses as a number.
    pub fn find_clip(&self, name: &str) -> Option<&Clip> {
        self.clips
            .iter()
            .find(|c| c.name.as_deref() == Some(name))
            .or_else(|| name.parse::<usize>().ok().and_then(|i| self.clips.get(i)))
    }

    /// The rig measured in `unit` where its file states none (BVH): a stated unit cannot be given another.
    pub fn given_unit(mut self, unit: Option<Unit>) -> Result<Rig, String> {
        match (self.unit, unit) {
            (Some(stated), Some(_)) => {
                return Err(format!(
                    "the file states its unit ({stated}); give one only to a file that does not (BVH)"
                ));
            }
            (None, given) => self.unit = given,
            (Some(_), None) => {}
        }
        Ok(self)
    }

    /// [`Rig::find_clip`]'s clip, or why there is none: "no animation `run` (available: 0 (walk), 1 (jog))".
    pub fn clip_named(&self, name: &str) -> Result<&Clip, String> {
        self.find_clip(name).ok_or_else(|| {
            let available: Vec<String> = self.clips.iter().map(|c| format!("{} ({})", c.index, c.label())).collect();
            let available = if available.is_empty() { "none".to_owned() } else { available.join(", ") };
            format!("no animation `{name}` (available: {available})")
        })
    }

    /// Per joint of skin `skin` (in the skin's joint order), whether some vertex of a mesh it deforms has a positive
    /// weight on it.
    pub fn weighted_joints(&self, skin: usize) -> Vec<bool> {
        let count = self.skins.get(skin).map_or(0, |s| s.joints.len());
        let mut weighted = vec![false; count];
        for mesh in self.meshes.iter().filter(|m| m.skin == Some(skin)) {
            for (joints, weights) in mesh.joints.iter().zip(&mesh.weights) {
                for (&j, &w) in joints.iter().zip(weights) {
                    if let Some(slot) = weighted.get_mut(usize::from(j)).filter(|_| w > 0.0) {
                        *slot = true;
                    }
                }
            }
        }
        weighted
    }

    /// The notes that name meshes of the file left out, and why ([`NOT_DRAWN_NOTE`]).
    pub fn meshes_not_drawn(&self) -> impl Iterator<Item = &str> {
        self.notes.iter().map(String::as_str).filter(|n| n.starts_with(NOT_DRAWN_NOTE))
    }

    /// For each bone, whether it is a conversion node: one at the top of the hierarchy (a root, or below conversion
    /// nodes only) that only changes axes or units ([`Transform::only_converts`]: a ratio of units, quarter turns)
    /// at rest and in every clip (which may key it, but only to hold one value), that carries bones or a mesh, that
    /// the file does not call a joint, and whose children the file says inherit it fully. Exporters put such nodes
    /// above a character to state its axes and unit (Blender's FBX armature turned −90° about X and scaled 100, a
    /// glTF exporter's `Armature`); two files of one character hold them or not, under any name, so comparisons
    /// recognise them by this role, and every mode leaves them outside the rig. A node whose children the file
    /// says compensate its scale (HumanIK's `Reference` null scaled 0.01 over segment-compensating hips) is part of
    /// the rig: its file evaluates it so.
    pub fn conversion_nodes(&self) -> Vec<bool> {
        let bones = self.skeleton.bones();
        let (mut carries, mut inherited_fully) = (vec![false; bones.len()], vec![true; bones.len()]);
        for bone in bones.iter().filter(|b| b.parent.is_some()) {
            let parent = bone.parent.unwrap_or_default();
            carries[parent] = true;
            inherited_fully[parent] &= bone.inherit == InheritMode::Full;
        }
        for mesh in &self.meshes {
            if let Some(c) = carries.get_mut(mesh.bone) {
                *c = true;
            }
        }
        let mut conversion = vec![false; bones.len()];
        for (i, bone) in bones.iter().enumerate() {
            let on_top = bone.parent.is_none_or(|p| conversion[p]);
            let outside = carries[i] && inherited_fully[i] && !self.skeleton.declared_figure(i);
            conversion[i] = on_top && outside && self.only_converts(i, &bone.rest);
        }
        conversion
    }

    /// The rig read as standing along `up` (a file whose axes are not stated, or stated wrongly), turned into
    /// bonescope's Y-up space above its roots with the file's own placement: every mode is still evaluated in the
    /// file's space, meshes and skins follow their bones.
    pub fn stood_up(self, up: UpAxis) -> Rig {
        self.turned(up.to_y_up(), up)
    }

    /// The rig, read as standing along `from`, read as standing along `to` instead.
    pub fn restood(self, from: UpAxis, to: UpAxis) -> Rig {
        self.turned(to.to_y_up() * from.to_y_up().inverse(), to)
    }

    fn turned(mut self, turn: glam::DMat4, up: UpAxis) -> Rig {
        let placement = self.skeleton.placement().clone();
        let conversion = turn * placement.conversion;
        self.skeleton = self.skeleton.placed(crate::model::Placement { conversion, ..placement });
        self.notes.retain(|n| !n.starts_with(UP_NOTE));
        if up != UpAxis::Y {
            self.notes.push(format!("{UP_NOTE}{}, turned to Y up", up.id().to_uppercase()));
        }
        self
    }

    /// Whether `bone` (at `rest`) only converts axes or units, at rest and throughout every clip.
    fn only_converts(&self, bone: usize, rest: &Transform) -> bool {
        let held = |clip: &Clip| clip.tracks_of(bone).map_or(Some(*rest), |tracks| tracks.held(rest));
        rest.only_converts() && self.clips.iter().all(|clip| held(clip).is_some_and(|h| h.only_converts()))
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{DQuat, DVec3, Quat, Vec3};

    use super::*;

    #[test]
    fn conversion_nodes_are_static_tops_that_only_convert_and_carry_something() {
        // Nodes the file does not call joints (nulls, an armature object), unless said otherwise.
        let bone = |name: &str, parent, rest| Bone { role: NodeRole::Helper, ..Bone::joint(name, parent, rest) };
        let centimetres = Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::splat(0.01));
        let turned = Transform::from_trs(DVec3::ZERO, DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2), DVec3::ONE);
        let up = Transform::from_trs(DVec3::Y, DQuat::IDENTITY, DVec3::ONE);
        let bones = vec![
            bone("Armature", None, turned),               // converts, carries `Scene`
            bone("Scene", Some(0), Transform::IDENTITY),  // below a conversion node, carries `hips`
            bone("hips", Some(1), up),                    // moved: a bone
            bone("marker", Some(2), Transform::IDENTITY), // identity, but below a bone
            bone("skin", None, turned),                   // carries a mesh
            bone("locator", None, Transform::IDENTITY),   // carries nothing
            bone("mover", None, Transform::IDENTITY),     // animated
            bone("passenger", Some(6), up),
            bone("keyed", None, Transform::IDENTITY), // keyed, but to hold a quarter turn throughout
            bone("rider", Some(8), up),
            Bone::joint("reference", None, centimetres), // the file calls it a joint
            Bone::joint("pelvis", Some(10), up),
            bone("null", None, centimetres), // a child compensates its scale: part of the rig
            Bone { inherit: InheritMode::SegmentCompensate, ..Bone::joint("compensating", Some(12), up) },
            bone("grown", None, Transform { scale: DVec3::splat(0.03), ..Transform::IDENTITY }), // not a unit
            Bone::joint("grown_hips", Some(14), up),
            bone("units", None, centimetres), // converts centimetres to metres
            Bone::joint("units_hips", Some(16), up),
        ];
        let times: Arc<[f64]> = Arc::from([0.0, 1.0]);
        let track = Track::new(times.clone(), vec![Vec3::ZERO, Vec3::X], Interpolation::Linear).unwrap();
        let quarter = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let held = Track::new(times, vec![quarter, quarter], Interpolation::Linear).unwrap();
        let tracks = vec![
            BoneTracks { translation: Some(track), ..BoneTracks::new(6) },
            BoneTracks { rotation: Some(held), ..BoneTracks::new(8) },
        ];
        let clip = Clip::new(0, None, tracks, vec![]);
        let rig = Rig {
            skeleton: Skeleton::new(bones).unwrap(),
            clips: vec![clip],
            meshes: vec![Mesh { bone: 4, ..Mesh::default() }],
            ..Rig::default()
        };
        let conversion: Vec<&str> = rig
            .conversion_nodes()
            .iter()
            .zip(rig.skeleton.bones())
            .filter(|(c, _)| **c)
            .map(|(_, b)| b.name.as_str())
            .collect();
        assert_eq!(conversion, ["Armature", "Scene", "skin", "keyed", "units"]);
    }

    #[test]
    fn a_viewer_opens_on_the_clip_that_keys_the_most_channels() {
        let track = |end: f64, to: Vec3| {
            let times: Arc<[f64]> = vec![0.0, end].into();
            Track::new(times, vec![Vec3::ZERO, to], Interpolation::Linear).unwrap()
        };
        let moving = |index: usize, bones: usize, end: f64| {
            let tracks =
                (0..bones).map(|b| BoneTracks { translation: Some(track(end, Vec3::X)), ..BoneTracks::new(b) });
            Clip::new(index, None, tracks.collect(), vec![])
        };
        let empty = |index: usize| Clip::new(index, Some("Take 001".into()), vec![], vec![]);
        let rig = |clips: Vec<Clip>| Rig { clips, ..Rig::default() };
        assert_eq!(rig(vec![]).opening_clip(), None);
        assert_eq!(rig(vec![moving(0, 1, 1.0), moving(1, 1, 5.0)]).opening_clip(), Some(0), "as many: the first");
        assert_eq!(rig(vec![moving(0, 1, 1.0), moving(1, 3, 0.5)]).opening_clip(), Some(1), "the most channels");
        assert_eq!(rig(vec![empty(0), moving(1, 1, 1.0)]).opening_clip(), Some(1), "an empty take is passed by");
        assert_eq!(rig(vec![empty(0), empty(1)]).opening_clip(), Some(0), "nothing moves: the first");
    }
}
