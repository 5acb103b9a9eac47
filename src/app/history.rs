//! Undo and redo of what the document evaluates. The history is the document's setups as they were, one after
//! another, and where the user stands among them: no command objects, the state is data, so going back is taking an
//! older one. A state is recorded at the end of a frame in which no pointer is down, so a slider dragged over many
//! frames is one step. Each step is called by what changed ([`Setup::change_from`]).
//!
//! The ghost is not history, but a step that changed it (a fix tried, which shows the clip as it was) gives it back
//! when undone; a ghost chosen between edits stays with the state it was chosen in.

use super::document::{Document, Ghost};
use crate::eval::{Setup, SetupError};

/// One state of the document.
#[derive(Clone, Debug, PartialEq)]
struct State {
    setup: Setup,
    ghost: Option<Ghost>,
    /// What made this state from the one before, for the Edit menu.
    label: String,
    /// Whether that step changed the ghost too (and so its undo gives the ghost back).
    moved_ghost: bool,
}

/// The document's states, oldest first, and the one it is in.
#[derive(Clone, Debug)]
pub struct History {
    states: Vec<State>,
    current: usize,
}

/// At most this many states are kept (the oldest go first): a setup is small, but a session may be long.
const KEPT: usize = 1000;

impl History {
    /// A history starting at what `doc` evaluates now.
    pub fn new(doc: &Document) -> Self {
        let state = State { setup: doc.setup().clone(), ghost: doc.ghost, label: String::new(), moved_ghost: false };
        History { states: vec![state], current: 0 }
    }

    /// Takes what `doc` evaluates now as a step, when it differs from the current state (after an undo, the steps
    /// that were undone are dropped); a ghost chosen alone is kept with the current state.
    pub fn record(&mut self, doc: &Document) {
        let now = &mut self.states[self.current];
        if *doc.setup() == now.setup {
            now.ghost = doc.ghost;
            return;
        }
        let label = doc.setup().change_from(&now.setup, &doc.rig);
        let moved_ghost = doc.ghost != now.ghost;
        self.states.truncate(self.current + 1);
        self.states.push(State { setup: doc.setup().clone(), ghost: doc.ghost, label, moved_ghost });
        if self.states.len() > KEPT {
            self.states.remove(0);
        }
        self.current = self.states.len() - 1;
    }

    /// Takes what `doc` evaluates now in place of the current step, as a step from the state before it (a fix
    /// tried instead of the one tried: one undo goes back to the state before either).
    pub fn record_in_place(&mut self, doc: &Document) {
        self.current = self.current.saturating_sub(1);
        self.record(doc);
    }

    /// What an undo would undo.
    pub fn undo_label(&self) -> Option<&str> {
        (self.current > 0).then(|| self.states[self.current].label.as_str())
    }

    /// What a redo would redo.
    pub fn redo_label(&self) -> Option<&str> {
        self.states.get(self.current + 1).map(|s| s.label.as_str())
    }

    /// Every step's label, oldest first (the first state's is empty: the document as opened), and which of them the
    /// document is in (those after it were undone).
    pub fn steps(&self) -> (Vec<&str>, usize) {
        (self.states.iter().map(|s| s.label.as_str()).collect(), self.current)
    }

    /// Takes `doc` back one step; on a state that no longer fits its rig (a reload lost the clip or bone it names),
    /// nothing changes and the error says why.
    pub fn undo(&mut self, doc: &mut Document) -> Result<(), SetupError> {
        if self.current == 0 {
            return Ok(());
        }
        let step = &self.states[self.current];
        self.restore(doc, self.current - 1, step.moved_ghost)?;
        self.current -= 1;
        Ok(())
    }

    /// Takes `doc` forward one undone step.
    pub fn redo(&mut self, doc: &mut Document) -> Result<(), SetupError> {
        let Some(step) = self.states.get(self.current + 1) else { return Ok(()) };
        self.restore(doc, self.current + 1, step.moved_ghost)?;
        self.current += 1;
        Ok(())
    }

    /// Puts `doc` in state `index`, its ghost too where `ghost` says so (a compared file's ghost only while one is
    /// compared).
    fn restore(&self, doc: &mut Document, index: usize, ghost: bool) -> Result<(), SetupError> {
        let state = &self.states[index];
        doc.set_setup(state.setup.clone())?;
        if ghost {
            doc.ghost = state.ghost.filter(|g| *g != Ghost::Compared || doc.compared.is_some());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::document::ModeScope;
    use crate::model::{InheritMode, ModeChoice};

    #[test]
    fn undo_and_redo_walk_the_steps_and_an_edit_drops_what_was_undone() {
        let mut doc = Document::demo();
        let mut history = History::new(&doc);
        let opened = doc.setup().clone();
        let forearm = doc.rig.skeleton.find("forearm").unwrap();
        assert_eq!((history.undo_label(), history.redo_label()), (None, None));
        doc.set_mode(forearm, ModeScope::Bone, ModeChoice::Mode(InheritMode::BlenderAligned));
        history.record(&doc);
        history.record(&doc);
        let aligned = doc.setup().clone();
        doc.set_clip(Some(1)).unwrap();
        history.record(&doc);
        assert_eq!(history.undo_label(), Some("animation bend"));
        history.undo(&mut doc).unwrap();
        assert_eq!((doc.setup(), history.undo_label()), (&aligned, Some("forearm → blender-aligned")));
        history.undo(&mut doc).unwrap();
        assert_eq!((doc.setup(), history.undo_label()), (&opened, None));
        history.undo(&mut doc).unwrap();
        assert_eq!(doc.setup(), &opened, "nothing before the first state");
        history.redo(&mut doc).unwrap();
        assert_eq!((doc.setup(), history.redo_label()), (&aligned, Some("animation bend")));
        doc.set_mode(0, ModeScope::All, ModeChoice::Mode(InheritMode::Full));
        history.record(&doc);
        assert_eq!((history.undo_label(), history.redo_label()), (Some("every bone → full"), None));
    }

    #[test]
    fn a_step_in_place_of_the_current_one_is_undone_to_the_state_before_it() {
        let mut doc = Document::demo();
        let mut history = History::new(&doc);
        let opened = doc.setup().clone();
        let forearm = doc.rig.skeleton.find("forearm").unwrap();
        doc.set_mode(forearm, ModeScope::Bone, ModeChoice::Mode(InheritMode::BlenderAligned));
        history.record(&doc);
        doc.set_setup(opened.clone()).unwrap();
        doc.set_mode(forearm, ModeScope::Bone, ModeChoice::Mode(InheritMode::Componentwise));
        history.record_in_place(&doc);
        assert_eq!(history.undo_label(), Some("forearm → componentwise"));
        history.undo(&mut doc).unwrap();
        assert_eq!((doc.setup(), history.undo_label()), (&opened, None), "one undo back to the state before both");
    }

    #[test]
    fn a_step_that_moved_the_ghost_gives_it_back_and_a_ghost_chosen_alone_is_no_step() {
        let mut doc = Document::demo();
        let mut history = History::new(&doc);
        let before = doc.ghost;
        doc.ghost = Some(Ghost::Unlayered);
        history.record(&doc);
        assert_eq!(history.undo_label(), None, "choosing a ghost is no step");
        let chosen = doc.ghost;
        doc.set_mode(0, ModeScope::Bone, ModeChoice::Mode(InheritMode::Full));
        history.record(&doc);
        history.undo(&mut doc).unwrap();
        assert_eq!(doc.ghost, chosen, "a mode edit leaves the ghost");
        doc.set_mode(1, ModeScope::Bone, ModeChoice::Mode(InheritMode::BlenderNone));
        doc.ghost = before;
        history.record(&doc);
        doc.ghost = None;
        history.undo(&mut doc).unwrap();
        assert_eq!(doc.ghost, chosen, "the step moved the ghost: its undo gives it back");
        history.redo(&mut doc).unwrap();
        assert_eq!(doc.ghost, before);
    }
}
