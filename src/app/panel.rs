//! What a panel is: one type behind [`Panel`], drawn on the state every panel works on ([`Shared`]). The window
//! lists the panels once; the layout, the View menu and the saved settings take the rest from the trait.

use super::document::Document;
use super::frame::CurrentPose;
use super::pane::{Pane, Place, Visibility};
use super::settings::Settings;
use super::work::{Results, Work};

/// At most this many bones are plotted at once (the most recently selected).
pub const MAX_PLOTTED: usize = 8;

/// What every panel works on.
pub struct Shared<'a> {
    pub doc: &'a mut Document,
    pub settings: &'a mut Settings,
    pub time: &'a mut f64,
    pub playing: &'a mut bool,
    /// Selected bones; the last one is the inspected one.
    pub selection: &'a mut Vec<usize>,
    /// The pose at the current time, and the ghost's.
    pub frame: &'a CurrentPose,
    /// What the background work has computed for the document.
    pub results: &'a Results,
    /// When the inspected bone (or, with none, any bone) is stretched, per the analysis.
    pub stretched: &'a [(f64, f64)],
    /// Where panels ask for more (an explanation, a bind check, a storage report).
    pub work: &'a mut Work,
    /// Set by a panel that asks for the history's Undo (as Edit → Undo does).
    pub undo_asked: &'a mut bool,
    /// Set by a panel whose edit this frame takes the place of the history's current step (a fix tried instead of
    /// the one tried), rather than adding one.
    pub step_in_place: &'a mut bool,
}

impl Shared<'_> {
    /// Selects one bone, or with `extend` adds/removes it from the selection.
    pub fn select(&mut self, bone: usize, extend: bool) {
        if extend {
            if let Some(i) = self.selection.iter().position(|&b| b == bone) {
                self.selection.remove(i);
            } else {
                self.selection.push(bone);
            }
        } else {
            self.selection.clear();
            self.selection.push(bone);
        }
    }

    /// `time` as the timeline shows it: in its unit, on the clip's clock (seconds with their frame beside them).
    pub fn time_text(&self, time: f64) -> String {
        self.settings.time_unit.format(time, self.doc.frame_rate())
    }

    pub fn inspected(&self) -> Option<usize> {
        self.selection.last().copied()
    }

    /// The bones whose curves are plotted.
    pub fn plotted(&self) -> Vec<usize> {
        plotted(self.selection)
    }
}

/// The bones of `selection` whose curves are plotted: the most recently selected ones, in the skeleton's order.
pub fn plotted(selection: &[usize]) -> Vec<usize> {
    let skip = selection.len().saturating_sub(MAX_PLOTTED);
    let mut bones: Vec<usize> = selection[skip..].to_vec();
    bones.sort_unstable();
    bones
}

/// One panel of the window.
pub trait Panel {
    /// Its id, and the title of its tab.
    fn pane(&self) -> Pane;

    /// Where the first arrangement puts it.
    fn place(&self) -> Place;

    /// Whether it shows in a new window.
    fn visibility(&self) -> Visibility {
        Visibility::Shown
    }

    /// Whether it draws the plotted bones' curves, which are then computed.
    fn plots_curves(&self) -> bool {
        false
    }

    fn ui(&mut self, ui: &mut egui::Ui, shared: &mut Shared);
}
