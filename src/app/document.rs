//! The open document: the loaded rig, where it came from, and the user's choices about it (clip, modes, ghost,
//! layers).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::compare::Compared;
use crate::eval::layers::LayerError;
use crate::eval::{Hierarchy, LayerStack, Layers, Pose};
use crate::import::{self, ImportError};
use crate::model::{Bone, Clip, DEFAULT_FRAME_RATE, InheritMode, Rig, Skeleton};

/// A second pose drawn translucent over the first and plotted dashed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ghost {
    /// Every bone under this mode (with the same layers).
    Mode(InheritMode),
    /// Every bone under the mode its file declares (with the same layers).
    Declared,
    /// The clip as authored: the document's modes without the layers.
    Unlayered,
    /// The file compared with the document (File → Compare with…).
    Compared,
}

impl Ghost {
    pub fn label(self) -> &'static str {
        match self {
            Ghost::Mode(mode) => mode.id(),
            Ghost::Declared => "declared",
            Ghost::Unlayered => "without layers",
            Ghost::Compared => "compared file",
        }
    }

    /// For a ghost of the document's own rig, its modes (given the document's `modes` and the skeleton's declared
    /// ones) and whether it goes through the layers; `None` for the compared file, another rig.
    pub fn evaluation(self, modes: &[InheritMode], skeleton: &Skeleton) -> Option<(Vec<InheritMode>, bool)> {
        match self {
            Ghost::Mode(mode) => Some((vec![mode; modes.len()], true)),
            Ghost::Declared => Some((skeleton.declared_modes(), true)),
            Ghost::Unlayered => Some((modes.to_vec(), false)),
            Ghost::Compared => None,
        }
    }
}

/// What a mode edit sets: one of the modes, or each bone's own as its file declares it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeChoice {
    Declared,
    Mode(InheritMode),
}

impl ModeChoice {
    /// "declared" first, then every mode.
    pub fn all() -> impl Iterator<Item = ModeChoice> {
        std::iter::once(ModeChoice::Declared).chain(InheritMode::ALL.into_iter().map(ModeChoice::Mode))
    }

    pub fn label(self) -> &'static str {
        match self {
            ModeChoice::Declared => "declared",
            ModeChoice::Mode(mode) => mode.id(),
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            ModeChoice::Declared => "each bone as its file declares it",
            ModeChoice::Mode(mode) => mode.description(),
        }
    }

    /// The mode this choice gives `bone`.
    fn mode_of(self, bone: &Bone) -> InheritMode {
        match self {
            ModeChoice::Declared => bone.inherit,
            ModeChoice::Mode(mode) => mode,
        }
    }
}

/// A loaded rig and the choices that change how it evaluates.
#[derive(Clone, Debug)]
pub struct Document {
    /// `None` for the built-in demo.
    pub path: Option<PathBuf>,
    pub rig: Arc<Rig>,
    /// One mode per bone, starting from what the file declares.
    pub modes: Vec<InheritMode>,
    pub ghost: Option<Ghost>,
    /// Index into `rig.clips`.
    pub clip: Option<usize>,
    /// The runtime techniques layered on the clip, prepared for the rig.
    layers: LayerStack,
    /// A frame rate the user chose instead of the clip's own.
    pub frame_rate_override: Option<f64>,
    /// A second file compared with this one.
    pub compared: Option<Arc<Compared>>,
}

impl Document {
    pub fn demo() -> Self {
        let mut doc = Document::new(None, import::demo_rig());
        // The demo exists to show shear: put the ghost where the shear disappears.
        doc.ghost = Some(Ghost::Mode(InheritMode::SegmentCompensate));
        doc
    }

    pub fn load(path: &Path) -> Result<Self, ImportError> {
        Ok(Document::new(Some(path.to_owned()), import::load(path)?))
    }

    /// A document on a rig that is already loaded (or generated).
    pub fn new(path: Option<PathBuf>, rig: Rig) -> Self {
        let modes = rig.skeleton.declared_modes();
        let clip = (!rig.clips.is_empty()).then_some(0);
        Document {
            path,
            rig: Arc::new(rig),
            modes,
            ghost: None,
            clip,
            layers: LayerStack::default(),
            frame_rate_override: None,
            compared: None,
        }
    }

    /// The same file re-read (after it changed on disk), keeping clip, modes and ghost where they still fit.
    pub fn reloaded(&self, rig: Rig) -> Self {
        let mut doc = Document::new(self.path.clone(), rig);
        if doc.modes.len() == self.modes.len() {
            doc.modes.clone_from(&self.modes);
        }
        doc.ghost = self.ghost;
        doc.frame_rate_override = self.frame_rate_override;
        doc.compared = self.compared.as_ref().map(|c| Arc::new(c.repaired(&doc.rig)));
        doc.clip = self.clip.filter(|&c| c < doc.rig.clips.len()).or(doc.clip);
        // Layers naming clips or bones the new file lacks are dropped rather than kept half-valid.
        let _ = doc.set_layers(self.layers());
        doc
    }

    pub fn layers(&self) -> &Layers {
        self.layers.layers()
    }

    /// The layers prepared for evaluating (a copy per evaluating thread: it holds scratch buffers).
    pub fn layer_stack(&self) -> &LayerStack {
        &self.layers
    }

    /// Replaces the layers; on an index the rig does not have, keeps the old ones.
    pub fn set_layers(&mut self, layers: &Layers) -> Result<(), LayerError> {
        self.layers = LayerStack::new(&self.rig, layers)?;
        Ok(())
    }

    pub fn title(&self) -> String {
        self.path.as_ref().map_or_else(
            || "demo rig".to_owned(),
            |p| {
                let name = p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned());
                // The window title: a file's name may hold control characters.
                crate::import::text::printable(&name).into_owned()
            },
        )
    }

    pub fn clip(&self) -> Option<&Clip> {
        self.clip.and_then(|c| self.rig.clips.get(c))
    }

    /// Frames per second of the timeline: the user's choice, else the clip's own (the file's rate, or its key
    /// spacing), else 30.
    pub fn frame_rate(&self) -> f64 {
        self.frame_rate_override.or_else(|| self.clip().map(Clip::frame_rate)).unwrap_or(DEFAULT_FRAME_RATE)
    }

    /// How long the timeline runs: the clip's duration, or what the layers make of it (a synced blend's cycle, a
    /// crossfade into a longer clip).
    pub fn duration(&self) -> f64 {
        self.layers.duration(&self.rig, self.clip())
    }

    /// How a ghost of this rig is evaluated, when one is shown: its modes, and whether through the layers.
    pub fn ghost_evaluation(&self) -> Option<(Vec<InheritMode>, bool)> {
        self.ghost.and_then(|ghost| ghost.evaluation(&self.modes, &self.rig.skeleton))
    }

    /// Compares this document with `compared`, drawn as the ghost.
    pub fn compare_with(&mut self, compared: Compared) {
        self.compared = Some(Arc::new(compared));
        self.ghost = Some(Ghost::Compared);
    }

    /// Stops comparing (a compared ghost goes too).
    pub fn stop_comparing(&mut self) {
        self.compared = None;
        if self.ghost == Some(Ghost::Compared) {
            self.ghost = None;
        }
    }

    /// The pose at `time` under `modes`, through the layers when `layered`.
    pub fn evaluate(&self, modes: &[InheritMode], time: f64, layered: bool) -> Pose {
        let hierarchy = Hierarchy::new(&self.rig.skeleton, modes);
        let mut pose = Pose::default();
        if layered && !self.layers().is_empty() {
            pose.evaluate_layered(&self.rig, self.clip(), &hierarchy, &mut self.layers.clone(), time);
        } else {
            pose.evaluate(&self.rig.skeleton, self.clip(), &hierarchy, time);
        }
        pose
    }

    /// Sets the mode of one bone, of its subtree, or of all bones.
    pub fn set_mode(&mut self, bone: usize, scope: ModeScope, choice: ModeChoice) {
        let skeleton = &self.rig.skeleton;
        for (b, m) in self.modes.iter_mut().enumerate() {
            if scope.applies(skeleton, b, bone) {
                *m = choice.mode_of(skeleton.bone(b));
            }
        }
    }

    /// The choice every bone of `scope` (around `bone`) matches: declared when each has its own, a mode when all
    /// share it (declared wins when both hold), `None` when they differ.
    pub fn current_choice(&self, bone: usize, scope: ModeScope) -> Option<ModeChoice> {
        let skeleton = &self.rig.skeleton;
        let in_scope = || (0..self.modes.len()).filter(move |&b| scope.applies(skeleton, b, bone));
        let matches = |choice: ModeChoice| in_scope().all(|b| self.modes[b] == choice.mode_of(skeleton.bone(b)));
        ModeChoice::all().find(|&choice| matches(choice))
    }

    /// The mode every bone shares, if they all share one.
    pub fn common_mode(&self) -> Option<InheritMode> {
        let first = *self.modes.first()?;
        self.modes.iter().all(|&m| m == first).then_some(first)
    }
}

/// Which bones an inheritance-mode edit applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeScope {
    Bone,
    Subtree,
    All,
}

impl ModeScope {
    /// Whether bone `b` is in this scope around `bone`.
    fn applies(self, skeleton: &Skeleton, b: usize, bone: usize) -> bool {
        match self {
            ModeScope::Bone => b == bone,
            ModeScope::Subtree => skeleton.is_in_subtree(b, bone),
            ModeScope::All => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_edits_reach_the_chosen_scope() {
        let mut doc = Document::demo();
        let forearm = doc.rig.skeleton.find("forearm").unwrap();
        doc.set_mode(forearm, ModeScope::Subtree, ModeChoice::Mode(InheritMode::SegmentCompensate));
        let names: Vec<&str> = doc
            .modes
            .iter()
            .enumerate()
            .filter(|(_, m)| **m == InheritMode::SegmentCompensate)
            .map(|(b, _)| doc.rig.skeleton.bone(b).name.as_str())
            .collect();
        assert_eq!(names, ["forearm", "hand"]);
        assert_eq!(doc.common_mode(), None);
        assert_eq!(
            doc.current_choice(forearm, ModeScope::Subtree),
            Some(ModeChoice::Mode(InheritMode::SegmentCompensate))
        );
        assert_eq!(doc.current_choice(0, ModeScope::All), None);
        doc.set_mode(0, ModeScope::All, ModeChoice::Mode(InheritMode::Componentwise));
        assert_eq!(doc.common_mode(), Some(InheritMode::Componentwise));
        assert_eq!(doc.current_choice(0, ModeScope::All), Some(ModeChoice::Mode(InheritMode::Componentwise)));
    }

    #[test]
    fn declared_sets_each_bone_back_to_its_file() {
        // The file's own modes differ per bone; any edit can be undone by choosing declared.
        let mut rig = import::demo_rig();
        let mut bones = rig.skeleton.bones().to_vec();
        bones[2].inherit = InheritMode::SegmentCompensate;
        rig.skeleton = Skeleton::new(bones).unwrap();
        let mut doc = Document::new(None, rig);
        let declared = doc.rig.skeleton.declared_modes();
        doc.set_mode(0, ModeScope::All, ModeChoice::Mode(InheritMode::Full));
        assert_ne!(doc.modes, declared);
        doc.set_mode(0, ModeScope::All, ModeChoice::Declared);
        assert_eq!(doc.modes, declared);
        assert_eq!(doc.current_choice(0, ModeScope::All), Some(ModeChoice::Declared));
        assert_eq!(doc.current_choice(2, ModeScope::Bone), Some(ModeChoice::Declared), "declared wins over its mode");
        let (modes, layered) = Ghost::Declared.evaluation(&doc.modes, &doc.rig.skeleton).unwrap();
        assert_eq!((modes, layered), (declared, true));
    }

    #[test]
    fn reloading_keeps_the_choices() {
        let mut doc = Document::demo();
        doc.clip = Some(1);
        doc.set_mode(2, ModeScope::Bone, ModeChoice::Mode(InheritMode::BlenderAligned));
        let blend = crate::eval::layers::Blend { clip: 0, weight: 0.3, sync: true, rotation: Default::default() };
        doc.set_layers(&Layers { blend: Some(blend), ..Layers::default() }).unwrap();
        let again = doc.reloaded(import::demo_rig());
        assert_eq!((again.clip, again.modes.clone(), again.ghost), (doc.clip, doc.modes.clone(), doc.ghost));
        assert_eq!(again.layers(), doc.layers());
        // A file that lost the blended clip keeps the document but drops the layers that no longer fit.
        let mut one_clip = import::demo_rig();
        one_clip.clips.truncate(1);
        doc.set_layers(&Layers { blend: Some(crate::eval::layers::Blend { clip: 1, ..blend }), ..Layers::default() })
            .unwrap();
        assert!(doc.reloaded(one_clip).layers().is_empty());
    }

    #[test]
    fn layers_naming_a_missing_clip_are_refused_and_the_old_ones_kept() {
        let mut doc = Document::demo();
        let before = doc.layers().clone();
        let blend = crate::eval::layers::Blend { clip: 7, weight: 0.5, sync: false, rotation: Default::default() };
        let error = doc.set_layers(&Layers { blend: Some(blend), ..Layers::default() }).unwrap_err();
        assert!(error.to_string().contains("no animation 7"), "{error}");
        assert_eq!(doc.layers(), &before);
    }
}
