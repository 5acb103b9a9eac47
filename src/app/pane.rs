//! A panel's place in the window as the settings keep it: its id, whether it shows, where it starts, and the tile
//! arrangement of them all.

use std::borrow::Cow;

/// A panel's id in the tile layout and the saved settings: its title.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct Pane(Cow<'static, str>);

impl Pane {
    pub const VIEWPORT: Pane = Pane::named("Viewport");
    pub const LAYERS: Pane = Pane::named("Layers");

    pub const fn named(title: &'static str) -> Pane {
        Pane(Cow::Borrowed(title))
    }

    pub fn title(&self) -> &str {
        &self.0
    }
}

/// Whether a panel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// Always (the View menu does not list it).
    Always,
    /// From the start, until hidden in the View menu.
    Shown,
    /// Once shown in the View menu.
    Hidden,
}

/// Where the first arrangement puts a panel: a column, and its share of that column's height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Place {
    Left,
    Centre(f32),
    /// A narrow window stacks the right-hand panels in one column; a wide one gives each a column.
    Right(f32),
}

/// The arrangement of the panels.
pub type Layout = egui_tiles::Tree<Pane>;
