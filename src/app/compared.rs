//! A second file compared with the document (File → Compare with…), as `bonescope diff` compares two files: its
//! bones and meshes paired with the document's by name, its pose drawn as the ghost over the document's, its curves
//! plotted dashed beside the document's, and each bone's largest difference over the clip, which the outliner badges
//! above a threshold; conversion nodes, which only state a file's axes and unit, are left out as `diff` leaves them.
//! The compared file is measured in the document's unit; where a file states none (BVH), the user gives it one
//! (the toolbar's unit pickers), and the axis it stands along where it lies down beside the document. The file is watched and reloaded like the document.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::identity::RigId;
use super::stance::Stance;
use crate::analysis::{Assessment, Tolerances};
use crate::diff::{match_bones, match_clips, match_meshes, standing_apart};
use crate::eval::layers::RotationInterpolation;
use crate::eval::{Evaluation, Setup, SkinningMethod};
use crate::import::{self, ImportError};
use crate::model::{Clip, Rig, Unit, UpAxis};
use crate::view::DrawnPose;

/// The compared file and how its bones and meshes stand for the document's.
#[derive(Clone, Debug)]
pub struct Compared {
    pub path: PathBuf,
    /// The file's rig; its unit the file's own, or the one the user gave it where the file states none.
    pub rig: Arc<Rig>,
    /// This rig paired with this document rig: a new pairing, or a unit given, is another.
    pub rig_id: RigId,
    /// Whether the file states its unit.
    states_unit: bool,
    /// The axis the file is read as standing along, and the axes the document and this file stand along as they
    /// play (the document's opening clip and its partner), where they differ ([`standing_apart`]).
    pub stance: Stance,
    /// The unit the file is measured in: the document's, or the one the user gave the document where its file
    /// states none.
    document_unit: Option<Unit>,
    /// Per bone of the document: its partner here.
    pub bones: Vec<Option<usize>>,
    /// Per bone of the document: why it is left out of the comparison, where it is.
    pub left_out: Vec<Option<LeftOut>>,
    /// Per mesh of the document: its partner here (same name and vertex count).
    pub meshes: Vec<Option<usize>>,
    /// Per clip of the document: the clip here that stands for it, as `bonescope diff` pairs them (else the first).
    clips: Vec<Option<usize>>,
    /// How its linear rotation keys are played: as the file says (slerp), or as a component-wise runtime (Blender,
    /// Unity, Unreal) plays them (`bonescope diff --interp`).
    pub played: RotationInterpolation,
}

/// Why a bone of the document is left out of a comparison, as `diff` leaves it out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeftOut {
    /// It only states the file's axes and unit.
    Conversion,
    /// It carries a skinned mesh, whose vertices follow the joints (the skin is compared).
    SkinnedMesh,
}

impl LeftOut {
    /// The word beside the bone's name.
    pub fn word(self) -> &'static str {
        match self {
            LeftOut::Conversion => "converts",
            LeftOut::SkinnedMesh => "skin",
        }
    }

    /// Why, in a sentence.
    pub fn why(self) -> &'static str {
        match self {
            LeftOut::Conversion => {
                "only states the file's axes and unit: left out of the comparison, as `diff` leaves it"
            }
            LeftOut::SkinnedMesh => {
                "carries a skinned mesh, whose vertices follow the joints: left out of the comparison (the skin is \
                 compared), as `diff` leaves it"
            }
        }
    }
}

impl Compared {
    /// Reads `path` and pairs it with the document's rig.
    pub fn load(path: &Path, document: &Rig) -> Result<Self, ImportError> {
        Ok(Compared::pair(path.to_owned(), import::load(path)?, document))
    }

    /// `rig` (read from `path`) paired with the document's rig.
    pub fn pair(path: PathBuf, rig: Rig, document: &Rig) -> Self {
        let matching = match_bones(document, &rig);
        let mut bones = vec![None; document.skeleton.len()];
        for &(a, b) in &matching.pairs {
            bones[a] = Some(b);
        }
        let mut left_out = vec![None; document.skeleton.len()];
        for (bones, why) in [(&matching.conversion_a, LeftOut::Conversion), (&matching.skinned_a, LeftOut::SkinnedMesh)]
        {
            for &a in bones {
                left_out[a] = Some(why);
            }
        }
        let mut meshes = vec![None; document.meshes.len()];
        for (a, b) in match_meshes(&document.meshes, &rig.meshes) {
            meshes[a] = Some(b);
        }
        let first = (!rig.clips.is_empty()).then_some(0);
        let mut clips = vec![first; document.clips.len()];
        for (a, b) in match_clips(&document.clips, &rig.clips).0 {
            clips[a] = Some(b);
        }
        let (states_unit, document_unit) = (rig.unit.is_some(), document.unit);
        let (rig, rig_id, played) = (Arc::new(rig), RigId::fresh(), RotationInterpolation::default());
        let opening = document.opening_clip();
        let apart = standing_apart((document, opening), (&rig, opening.and_then(|o| clips[o])));
        let stance = Stance { up: UpAxis::Y, apart };
        Compared { path, rig, rig_id, states_unit, stance, document_unit, bones, left_out, meshes, clips, played }
    }

    /// The same file paired with another document rig (the document was reloaded), keeping the units given and
    /// how it is played.
    pub fn repaired(&self, document: &Rig) -> Self {
        let repaired = Compared::pair(self.path.clone(), (*self.rig).clone(), document);
        let document_unit = document.unit.or(self.document_unit);
        let stance = Stance { up: self.stance.up, ..repaired.stance };
        Compared { states_unit: self.states_unit, stance, document_unit, played: self.played, ..repaired }
    }

    /// The file read again after it changed on disk, paired with `document`, keeping the units and the up axis the
    /// user gave and how it is played.
    pub fn reloaded(&self, document: &Rig) -> Result<Self, ImportError> {
        let mut rig = import::load(&self.path)?.stood_up(self.stance.up);
        if rig.unit.is_none() && !self.states_unit {
            rig.unit = self.rig.unit;
        }
        let fresh = Compared::pair(self.path.clone(), rig, document);
        let stance = Stance { up: self.stance.up, ..fresh.stance };
        Ok(Compared { document_unit: self.document_unit, played: self.played, stance, ..fresh })
    }

    /// Whether the file states its unit (else the user gives it one).
    pub fn states_unit(&self) -> bool {
        self.states_unit
    }

    /// The same file taken in `unit` (it states none): another rig to compare.
    pub fn given_unit(&self, unit: Unit) -> Self {
        let mut rig = (*self.rig).clone();
        rig.unit = Some(unit);
        Compared { rig: Arc::new(rig), rig_id: RigId::fresh(), ..self.clone() }
    }

    /// The same file read as standing along `up` beside `document`: another rig to compare.
    pub fn given_up(&self, up: UpAxis, document: &Rig) -> Self {
        let rig = (*self.rig).clone().restood(self.stance.up, up);
        let opening = document.opening_clip();
        let apart =
            standing_apart((document, opening), (&rig, opening.and_then(|o| self.clips.get(o).copied().flatten())));
        Compared { rig: Arc::new(rig), rig_id: RigId::fresh(), stance: Stance { up, apart }, ..self.clone() }
    }

    /// The same measured in `unit`, the document's where its file states none.
    pub fn in_document_unit(&self, unit: Unit) -> Self {
        Compared { document_unit: Some(unit), ..self.clone() }
    }

    /// The same, its rotation keys played by `played`.
    pub fn played_by(&self, played: RotationInterpolation) -> Self {
        Compared { played, ..self.clone() }
    }

    /// The document's unit and the compared file's, as the comparison takes them.
    pub fn units(&self) -> [Option<Unit>; 2] {
        [self.document_unit, self.rig.unit]
    }

    /// The file's name, for labels.
    pub fn title(&self) -> String {
        let name =
            self.path.file_name().map_or_else(|| self.path.display().to_string(), |n| n.to_string_lossy().into_owned());
        crate::import::text::printable(&name).into_owned()
    }

    /// How many of the document's bones (those left out aside) have no partner here.
    pub fn unpaired(&self) -> usize {
        self.bones.iter().zip(&self.left_out).filter(|(b, why)| b.is_none() && why.is_none()).count()
    }

    /// The clip here (an index) that stands for the document's clip `clip` (an index; `None`: the rest pose, for
    /// which this file plays its first clip).
    fn partner(&self, clip: Option<usize>) -> Option<usize> {
        match clip {
            Some(clip) => self.clips.get(clip).copied().flatten(),
            None => (!self.rig.clips.is_empty()).then_some(0),
        }
    }

    /// The clip here that stands for the document's clip `clip`.
    pub fn clip_for(&self, clip: Option<usize>) -> Option<&Clip> {
        self.partner(clip).map(|c| &self.rig.clips[c])
    }

    /// What is evaluated of this file for the document's clip `clip` (an index): the clip that stands for it, as
    /// the file declares, measured in the document's unit, its rotation keys played as chosen.
    pub fn setup(&self, clip: Option<usize>) -> Setup {
        let mut setup = Setup { clip: self.partner(clip), unit: self.document_unit, ..Setup::default() };
        setup.layers.interpolation.rotation = self.played;
        setup
    }

    /// This file evaluated as [`Compared::setup`] says.
    pub fn evaluation(&self, clip: Option<usize>) -> Evaluation<'_> {
        let setup = self.setup(clip);
        // The clip is the file's own, and nothing names a bone or another clip.
        Evaluation::of(&self.rig, &setup).unwrap_or_else(|_| Evaluation::declared(&self.rig, None))
    }

    /// The ghost at `time`: this file's pose on the document's bones (a bone without a partner stays where the
    /// document puts it, under its pose), the paired meshes skinned (the others not drawn).
    pub fn ghost(
        &self,
        clip: Option<usize>,
        primary: &DrawnPose,
        time: f64,
        skinning: SkinningMethod,
        tolerances: &Tolerances,
    ) -> DrawnPose {
        let evaluation = self.evaluation(clip).with_skinning(skinning);
        let pose = evaluation.pose_at(time);
        let model: Vec<_> =
            self.bones.iter().zip(&primary.model).map(|(b, own)| b.map_or(*own, |b| pose.model.model[b])).collect();
        let assessments = Assessment::all(&model, tolerances);
        let meshes = self
            .meshes
            .iter()
            .map(|m| {
                let mut positions = Vec::new();
                if let Some(m) = m {
                    evaluation.skin(&pose, *m, &mut positions);
                }
                positions
            })
            .collect();
        DrawnPose {
            model,
            findings: assessments.iter().map(|a| a.findings).collect(),
            shear_deg: assessments.iter().map(|a| a.shear_deg).collect(),
            meshes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::angle_between;
    use crate::model::{Bone, BoneTracks, Interpolation, Skeleton, Track, Transform};

    #[test]
    fn a_compared_file_played_by_nlerp_is_where_nlerp_puts_it() {
        // One bone turned a quarter turn about Z over a second by two linear keys, compared with itself played by
        // nlerp: 13/60 s in, nlerp is at 2·atan(t·sin φ / (1 − t + t·cos φ)) with φ = 45°, slerp at t·90°,
        // 0.918805° apart.
        let bone = Bone::joint("b", None, Transform::IDENTITY);
        let mut tracks = BoneTracks::new(0);
        let keys = vec![glam::Quat::IDENTITY, glam::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)];
        tracks.rotation = Some(Track::new(Arc::from([0.0, 1.0].as_slice()), keys, Interpolation::Linear).unwrap());
        let clip = Clip::new(0, Some("turn".into()), vec![tracks], vec![]);
        let rig = Rig { skeleton: Skeleton::new(vec![bone]).unwrap(), clips: vec![clip], ..Rig::default() };
        let played =
            Compared { played: RotationInterpolation::Nlerp, ..Compared::pair("turn".into(), rig.clone(), &rig) };
        let time = 13.0 / 60.0;
        let rotation = |e: Evaluation| e.pose_at(time).local[0].rotation;
        let own = rotation(Evaluation::declared(&rig, rig.clips.first()));
        let apart = angle_between(own, rotation(played.evaluation(Some(0)))).to_degrees();
        assert!((apart - 0.918805).abs() < 1e-4, "{apart}°");
        assert_eq!(rotation(played.repaired(&rig).evaluation(Some(0))), rotation(played.evaluation(Some(0))));
    }

    #[test]
    fn a_file_compared_with_itself_pairs_everything_and_ghosts_its_pose() {
        let rig = import::demo_rig();
        let compared = Compared::pair(PathBuf::from("demo.glb"), rig.clone(), &rig);
        assert_eq!(compared.unpaired(), 0);
        assert!(compared.meshes.iter().all(Option::is_some));
        let pose = Evaluation::declared(&rig, rig.clips.first()).pose_at(0.5);
        let primary = DrawnPose::from_model(
            &rig,
            pose.model.model.clone(),
            &pose.morph,
            SkinningMethod::AsFile,
            &Tolerances::default(),
        );
        let ghost = compared.ghost(Some(0), &primary, 0.5, SkinningMethod::AsFile, &Tolerances::default());
        assert_eq!(ghost.model, primary.model);
        assert_eq!(ghost.meshes, primary.meshes);
    }

    #[test]
    fn a_reload_keeps_the_unit_given_to_a_file_that_states_none() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("walk.bvh");
        let bvh = "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n End Site\n {\n  \
                   OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.0333333\n0 0 0\n";
        std::fs::write(&path, bvh).unwrap();
        let document = import::demo_rig();
        let loaded = Compared::load(&path, &document).unwrap();
        assert_eq!(loaded.units()[1], None, "a BVH states no unit");
        let centimetres: Unit = "cm".parse().unwrap();
        let mut given = loaded.clone();
        Arc::make_mut(&mut given.rig).unit = Some(centimetres);
        std::fs::write(&path, bvh.replace("0 1 0", "0 2 0")).unwrap();
        let reloaded = given.reloaded(&document).unwrap();
        assert_eq!(reloaded.units(), given.units(), "the unit picked survives the file's change");
        assert_ne!(reloaded.rig.skeleton.len(), 0);
    }

    #[test]
    fn clips_pair_by_label_whatever_their_order() {
        let rig = import::demo_rig();
        let mut other = rig.clone();
        other.clips.reverse();
        let compared = Compared::pair(PathBuf::from("other.glb"), other, &rig);
        for (c, clip) in rig.clips.iter().enumerate() {
            assert_eq!(compared.clip_for(Some(c)).map(Clip::label), Some(clip.label()));
        }
        assert_eq!(compared.clip_for(None).map(Clip::label), compared.rig.clips.first().map(Clip::label));
    }
}
