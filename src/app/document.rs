//! The open document: the loaded rig, where it came from, what is evaluated of it (its [`Setup`]: clip, modes,
//! layers), the ghost and the compared file.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::compared::Compared;
use super::identity::RigId;
use super::stance::Stance;
use crate::analysis::ScanOptions;
use crate::eval::{Evaluation, LayerStack, Layers, Setup, SetupError};
use crate::import::{self, ImportError};
use crate::model::{Choice, Clip, DEFAULT_FRAME_RATE, InheritMode, ModeChoice, Modes, Rig, Skeleton, Span, UpAxis};

/// A second pose drawn translucent over the first and plotted dashed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ghost {
    /// The document's clip through the same layers under other modes.
    Modes(ModeChoice),
    /// The clip as authored: the document's modes without the layers.
    Unlayered,
    /// The file compared with the document (File → Compare with…): its pose on the paired bones.
    Compared,
}

impl Ghost {
    pub fn label(&self) -> &'static str {
        match self {
            Ghost::Modes(choice) => choice.id(),
            Ghost::Unlayered => "without layers",
            Ghost::Compared => "compared file",
        }
    }

    /// What the ghost evaluates of the document's rig, given what the document evaluates; `None` for the compared
    /// file, another rig, whose pose is paired bone by bone ([`Compared::ghost`]).
    pub fn setup(&self, document: &Setup) -> Option<Setup> {
        match *self {
            Ghost::Modes(choice) => Some(Setup { modes: Modes::all(choice), ..document.clone() }),
            Ghost::Unlayered => Some(Setup { layers: Layers::default(), ..document.clone() }),
            Ghost::Compared => None,
        }
    }
}

/// A loaded rig and what is evaluated of it.
#[derive(Clone, Debug)]
pub struct Document {
    /// `None` for the built-in demo.
    pub path: Option<PathBuf>,
    pub rig: Arc<Rig>,
    pub rig_id: RigId,
    /// What is evaluated: clip, modes, layers. Changed only through the checks of [`Document::set_setup`].
    setup: Setup,
    /// The setup's modes, one per bone.
    modes: Vec<InheritMode>,
    /// The setup's layers prepared for the rig.
    layers: LayerStack,
    /// Never [`Ghost::Compared`] without a compared file.
    pub ghost: Option<Ghost>,
    /// A frame rate the user chose instead of the clip's own.
    pub frame_rate_override: Option<f64>,
    /// A second file compared with this one.
    pub compared: Option<Arc<Compared>>,
    /// The axis the file is read as standing along, and where it lies down in the view's Y-up space as it plays
    /// (the view's axis and its own).
    pub stance: Stance,
}

impl Document {
    pub fn demo() -> Self {
        let mut doc = Document::new(None, import::demo_rig());
        // The demo exists to show shear: put the ghost where the shear disappears.
        doc.ghost = Some(Ghost::Modes(ModeChoice::Mode(InheritMode::SegmentCompensate)));
        doc
    }

    pub fn load(path: &Path) -> Result<Self, ImportError> {
        Ok(Document::new(Some(path.to_owned()), import::load(path)?))
    }

    /// A document on a rig that is already loaded (or generated), as its file declares it.
    pub fn new(path: Option<PathBuf>, rig: Rig) -> Self {
        let setup = Setup::declared(&rig);
        let modes = rig.skeleton.declared_modes();
        let lies = crate::diff::standing(&rig, rig.opening_clip()).filter(|&up| up != UpAxis::Y);
        let stance = Stance { up: UpAxis::Y, apart: lies.map(|up| [UpAxis::Y, up]) };
        Document {
            path,
            rig: Arc::new(rig),
            rig_id: RigId::fresh(),
            setup,
            modes,
            layers: LayerStack::default(),
            ghost: None,
            frame_rate_override: None,
            compared: None,
            stance,
        }
    }

    /// The same file re-read (after it changed on disk), keeping clip, modes, ghost, layers and the axis it was
    /// stood along where they still fit. Layers naming clips or bones the new file lacks are dropped rather than
    /// kept half-valid: the error says why, for the user.
    pub fn reloaded(&self, rig: Rig) -> (Self, Option<SetupError>) {
        let mut doc = Document::new(self.path.clone(), rig.stood_up(self.stance.up));
        doc.stance.up = self.stance.up;
        doc.frame_rate_override = self.frame_rate_override;
        doc.compared = self.compared.as_ref().map(|c| Arc::new(c.repaired(&doc.rig)));
        doc.ghost = self.ghost.filter(|ghost| *ghost != Ghost::Compared || doc.compared.is_some());
        // Bones given their own mode are kept where the bones are the same ones (as many as before).
        let modes = match doc.rig.skeleton.len() == self.rig.skeleton.len() {
            true => self.setup.modes.clone(),
            false => Modes::all(self.setup.modes.all),
        };
        let clip = self.setup.clip.filter(|&c| c < doc.rig.clips.len()).or(doc.setup.clip);
        let kept = Setup { clip, modes, layers: Layers::default(), ..self.setup.clone() };
        // The clip and the bones are the rig's: it fits.
        let _ = doc.set_setup(kept);
        let dropped = doc.set_layers(&self.setup.layers).err();
        (doc, dropped)
    }

    /// The same file read as standing along `up` (a BVH lying down in the view), keeping what is evaluated: another
    /// rig, the same bones.
    pub fn stood_up(&self, up: UpAxis) -> Self {
        let as_read = (*self.rig).clone().restood(self.stance.up, UpAxis::Y);
        let turned = Document { stance: Stance { up, ..self.stance }, ..self.clone() };
        // The same bones, clips and layers: nothing is dropped.
        turned.reloaded(as_read).0
    }

    /// What is evaluated.
    pub fn setup(&self) -> &Setup {
        &self.setup
    }

    /// Evaluates `setup` from now on; on one that does not fit the rig, keeps the old one.
    pub fn set_setup(&mut self, setup: Setup) -> Result<(), SetupError> {
        self.layers = setup.prepare(&self.rig)?;
        self.modes = setup.modes.resolve(&self.rig.skeleton);
        self.setup = setup;
        Ok(())
    }

    pub fn layers(&self) -> &Layers {
        &self.setup.layers
    }

    /// Replaces the layers; on an index the rig does not have, keeps the old ones.
    pub fn set_layers(&mut self, layers: &Layers) -> Result<(), SetupError> {
        self.set_setup(Setup { layers: layers.clone(), ..self.setup.clone() })
    }

    /// Plays the clip `clip` (an index into the rig's clips; `None`: the rest pose).
    pub fn set_clip(&mut self, clip: Option<usize>) -> Result<(), SetupError> {
        self.set_setup(Setup { clip, ..self.setup.clone() })
    }

    /// One mode per bone.
    pub fn modes(&self) -> &[InheritMode] {
        &self.modes
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
        self.setup.clip.and_then(|c| self.rig.clips.get(c))
    }

    /// Frames per second of the timeline: the user's choice, else the clip's own (the file's rate, or its key
    /// spacing), else 30.
    pub fn frame_rate(&self) -> f64 {
        self.frame_rate_override.or_else(|| self.clip().map(Clip::frame_rate)).unwrap_or(DEFAULT_FRAME_RATE)
    }

    /// Samples per second of the whole-clip analysis: the clip's own frames, and at least `scan`'s default rate, so
    /// that a clip keyed sparsely is examined between its keys and the app samples where `scan` does (the worst
    /// shear is refined between samples whatever the rate; a stretch angle that spikes between two samples is not).
    pub fn analysis_rate(&self) -> f64 {
        self.frame_rate().max(ScanOptions::default().rate)
    }

    /// Where the timeline runs on the clip's own clock: from the clip's start for as long as the clip plays, or as
    /// long as the layers make it (a synced blend's cycle, a crossfade into a longer clip); at 0 for the rest pose.
    pub fn span(&self) -> Span {
        let start = self.clip().map_or(0.0, |clip| clip.span().start);
        Span::new(start, start + self.layers.length(&self.rig, self.clip()))
    }

    /// What the document shows: its clip under its modes, through its layers.
    pub fn evaluation(&self) -> Evaluation<'_> {
        Evaluation::prepared(&self.rig, &self.setup, self.layers.clone())
    }

    /// What the ghost evaluates of this rig, when the ghost is one (a compared file's is its own).
    pub fn ghost_setup(&self) -> Option<Setup> {
        self.ghost?.setup(&self.setup)
    }

    /// The ghost's evaluation of this rig, when the ghost is one (a compared file's is its own:
    /// [`Compared::ghost`]).
    pub fn ghost_evaluation(&self) -> Option<Evaluation<'_>> {
        // A ghost's setup differs from the document's in its modes (the same layers: the stack prepared for the
        // document serves, not prepared again every frame) or has no layers at all.
        let setup = self.ghost_setup()?;
        let layers = if setup.layers == self.setup.layers { self.layers.clone() } else { LayerStack::default() };
        Some(Evaluation::prepared(&self.rig, &setup, layers))
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

    /// Sets the mode of one bone, of its subtree, or of all bones.
    pub fn set_mode(&mut self, bone: usize, scope: ModeScope, choice: ModeChoice) {
        let skeleton = &self.rig.skeleton;
        let modes = match scope {
            ModeScope::All => Modes::all(choice),
            _ => {
                let mut modes = self.setup.modes.clone();
                for b in (0..skeleton.len()).filter(|&b| scope.applies(skeleton, b, bone)) {
                    modes.set(skeleton, b, choice);
                }
                modes
            }
        };
        let setup = Setup { modes, ..self.setup.clone() };
        // The modes name only the rig's bones, and nothing else changed.
        let _ = self.set_setup(setup);
    }

    /// The choice every bone of `scope` (around `bone`) matches: declared when each has its own, a mode when all
    /// share it (declared wins when both hold), `None` when they differ.
    pub fn current_choice(&self, bone: usize, scope: ModeScope) -> Option<ModeChoice> {
        let skeleton = &self.rig.skeleton;
        let in_scope = || (0..self.modes.len()).filter(move |&b| scope.applies(skeleton, b, bone));
        let matches =
            |choice: ModeChoice| in_scope().all(|b| self.modes[b] == choice.mode_for(skeleton.bone(b).inherit));
        ModeChoice::ALL.iter().copied().find(|&choice| matches(choice))
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
            .modes()
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
        assert_ne!(doc.modes(), declared);
        doc.set_mode(0, ModeScope::All, ModeChoice::Declared);
        assert_eq!(doc.modes(), declared);
        assert_eq!(doc.current_choice(0, ModeScope::All), Some(ModeChoice::Declared));
        assert_eq!(doc.current_choice(2, ModeScope::Bone), Some(ModeChoice::Declared), "declared wins over its mode");
        doc.set_layers(&Layers { bind_weight: 0.5, ..Layers::default() }).unwrap();
        doc.ghost = Some(Ghost::Modes(ModeChoice::Declared));
        let ghost = doc.ghost_evaluation().unwrap();
        assert_eq!((ghost.modes(), ghost.layers().is_some()), (declared.as_slice(), true), "the same layers");
        doc.ghost = Some(Ghost::Unlayered);
        let unlayered = doc.ghost_evaluation().unwrap();
        assert_eq!((unlayered.modes(), unlayered.layers().is_none()), (doc.modes(), true));
    }

    #[test]
    fn the_timeline_runs_on_the_clips_clock_and_its_layers_count_from_its_start() {
        // The demo's stretch on a file's clock that starts at 0.5 s (an FBX take's stored start).
        let mut rig = import::demo_rig();
        rig.clips[0] = rig.clips[0].clone().with_span(Span::new(0.5, 2.5));
        let mut doc = Document::new(None, rig);
        doc.set_clip(Some(0)).unwrap();
        assert_eq!(doc.span(), Span::new(0.5, 2.5));
        // A crossfade 1.8 s after the clip's start runs on until the incoming clip ends.
        let incoming = doc.rig.clips[1].span().length();
        let crossfade = crate::eval::layers::Crossfade { clip: 1, at: 1.8, duration: 0.2, curve: Default::default() };
        doc.set_layers(&Layers { crossfade: Some(crossfade), ..Layers::default() }).unwrap();
        assert_eq!(doc.span(), Span::new(0.5, 0.5 + (1.8 + incoming)));
    }

    #[test]
    fn reloading_keeps_the_choices() {
        let mut doc = Document::demo();
        doc.set_clip(Some(1)).unwrap();
        doc.set_mode(2, ModeScope::Bone, ModeChoice::Mode(InheritMode::BlenderAligned));
        let blend = crate::eval::layers::Blend { clip: 0, weight: 0.3, sync: true, rotation: Default::default() };
        doc.set_layers(&Layers { blend: Some(blend), ..Layers::default() }).unwrap();
        let (again, dropped) = doc.reloaded(import::demo_rig());
        assert_eq!(dropped, None);
        assert_eq!((again.setup(), again.ghost), (doc.setup(), doc.ghost));
        assert_ne!(again.rig_id, doc.rig_id, "a reload is another rig");
        // A file that lost the blended clip keeps the document but drops the layers that no longer fit.
        let mut one_clip = import::demo_rig();
        one_clip.clips.truncate(1);
        doc.set_layers(&Layers { blend: Some(crate::eval::layers::Blend { clip: 1, ..blend }), ..Layers::default() })
            .unwrap();
        let (again, dropped) = doc.reloaded(one_clip);
        assert!(again.layers().is_empty());
        assert!(dropped.unwrap().to_string().contains("no animation 1"), "the user is told why");
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
