//! The open document: the loaded rig, where it came from, and the user's choices about it (clip, modes, ghost).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::import::{self, ImportError};
use crate::model::{Clip, InheritMode, Rig};

/// A loaded rig and the choices that change how it evaluates.
#[derive(Clone, Debug)]
pub struct Document {
    /// `None` for the built-in demo.
    pub path: Option<PathBuf>,
    pub rig: Arc<Rig>,
    /// One mode per bone, starting from what the file declares.
    pub modes: Vec<InheritMode>,
    /// A second mode for every bone, drawn and plotted as a translucent ghost.
    pub ghost: Option<InheritMode>,
    /// Index into `rig.clips`.
    pub clip: Option<usize>,
}

impl Document {
    pub fn demo() -> Self {
        let mut doc = Document::new(None, import::demo_rig());
        // The demo exists to show shear: put the ghost where the shear disappears.
        doc.ghost = Some(InheritMode::SegmentCompensate);
        doc
    }

    pub fn load(path: &Path) -> Result<Self, ImportError> {
        Ok(Document::new(Some(path.to_owned()), import::load(path)?))
    }

    /// A document on a rig that is already loaded (or generated).
    pub fn new(path: Option<PathBuf>, rig: Rig) -> Self {
        let modes = rig.skeleton.declared_modes();
        let clip = (!rig.clips.is_empty()).then_some(0);
        Document { path, rig: Arc::new(rig), modes, ghost: None, clip }
    }

    /// The same file re-read (after it changed on disk), keeping clip, modes and ghost where they still fit.
    pub fn reloaded(&self, rig: Rig) -> Self {
        let mut doc = Document::new(self.path.clone(), rig);
        if doc.modes.len() == self.modes.len() {
            doc.modes.clone_from(&self.modes);
        }
        doc.ghost = self.ghost;
        doc.clip = self.clip.filter(|&c| c < doc.rig.clips.len()).or(doc.clip);
        doc
    }

    pub fn title(&self) -> String {
        self.path.as_ref().map_or_else(
            || "demo rig".to_owned(),
            |p| p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned()),
        )
    }

    pub fn clip(&self) -> Option<&Clip> {
        self.clip.and_then(|c| self.rig.clips.get(c))
    }

    pub fn duration(&self) -> f64 {
        self.clip().map_or(0.0, Clip::duration)
    }

    /// The modes of the ghost pose, when a ghost is shown.
    pub fn ghost_modes(&self) -> Option<Vec<InheritMode>> {
        self.ghost.map(|mode| vec![mode; self.modes.len()])
    }

    /// Sets the mode of one bone, of its subtree, or of all bones.
    pub fn set_mode(&mut self, bone: usize, scope: ModeScope, mode: InheritMode) {
        let skeleton = &self.rig.skeleton;
        for (b, m) in self.modes.iter_mut().enumerate() {
            let applies = match scope {
                ModeScope::Bone => b == bone,
                ModeScope::Subtree => skeleton.is_in_subtree(b, bone),
                ModeScope::All => true,
            };
            if applies {
                *m = mode;
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_edits_reach_the_chosen_scope() {
        let mut doc = Document::demo();
        let forearm = doc.rig.skeleton.find("forearm").unwrap();
        doc.set_mode(forearm, ModeScope::Subtree, InheritMode::SegmentCompensate);
        let names: Vec<&str> = doc
            .modes
            .iter()
            .enumerate()
            .filter(|(_, m)| **m == InheritMode::SegmentCompensate)
            .map(|(b, _)| doc.rig.skeleton.bone(b).name.as_str())
            .collect();
        assert_eq!(names, ["forearm", "hand"]);
        assert_eq!(doc.common_mode(), None);
        doc.set_mode(0, ModeScope::All, InheritMode::Componentwise);
        assert_eq!(doc.common_mode(), Some(InheritMode::Componentwise));
    }

    #[test]
    fn reloading_keeps_the_choices() {
        let mut doc = Document::demo();
        doc.clip = Some(1);
        doc.set_mode(2, ModeScope::Bone, InheritMode::BlenderAligned);
        let again = doc.reloaded(import::demo_rig());
        assert_eq!((again.clip, again.modes.clone(), again.ghost), (doc.clip, doc.modes.clone(), doc.ghost));
    }
}
