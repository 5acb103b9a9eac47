//! The panels as tiles: the user tabs, splits, drags (by the tab) and resizes them, and the arrangement persists
//! with the settings. The first arrangement fits the window's width: below [`WIDE`] the Inspector and the Layers
//! share one column, one above the other, so that each keeps the width its numbers need; wider, each has its own.

use egui_tiles::{Container, Linear, LinearDir, SimplificationOptions, TileId, Tiles, UiResponse};

use super::{Shared, inspector, layers, outliner, plots, viewport};
use crate::app::Settings;

/// One panel of the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Pane {
    Viewport,
    Outliner,
    Inspector,
    Layers,
    Plots,
}

impl Pane {
    pub const ALL: [Pane; 5] = [Pane::Viewport, Pane::Outliner, Pane::Inspector, Pane::Layers, Pane::Plots];

    pub fn title(self) -> &'static str {
        match self {
            Pane::Viewport => "Viewport",
            Pane::Outliner => "Skeleton",
            Pane::Inspector => "Inspector",
            Pane::Layers => "Layers",
            Pane::Plots => "Plots",
        }
    }

    /// Whether the settings show this panel (the viewport and the skeleton always show).
    fn shown(self, settings: &Settings) -> bool {
        match self {
            Pane::Viewport | Pane::Outliner => true,
            Pane::Inspector => settings.show_inspector,
            Pane::Layers => settings.show_layers,
            Pane::Plots => settings.show_plots,
        }
    }
}

/// The arrangement of the panels.
pub type Layout = egui_tiles::Tree<Pane>;

/// From this window width (points) on, the Inspector and the Layers stand side by side.
pub const WIDE: f32 = 1600.0;

/// The widths the side panels start with, in points: the skeleton's names and the inspector's four matrix columns.
const OUTLINER_WIDTH: f32 = 280.0;
const SIDE_WIDTH: f32 = 340.0;

/// The share of the centre column's height the plots start with.
const PLOTS_SHARE: f32 = 0.3;

/// The first arrangement for a window `width` points wide: the skeleton left, the viewport over the plots in the
/// middle, the Inspector and Layers right.
pub fn default_layout(width: f32) -> Layout {
    // A small window gives each side a share instead, so that the viewport keeps over 40 % of it.
    let (outliner_width, side_width) = (OUTLINER_WIDTH.min(0.22 * width), SIDE_WIDTH.min(0.32 * width));
    let mut tiles = Tiles::default();
    let [viewport, outliner, inspector, layers, plots] = Pane::ALL.map(|pane| tiles.insert_pane(pane));
    let centre = linear(&mut tiles, LinearDir::Vertical, &[(viewport, 1.0 - PLOTS_SHARE), (plots, PLOTS_SHARE)]);
    let side = |tiles: &mut Tiles<Pane>| {
        if width < WIDE {
            vec![(linear(tiles, LinearDir::Vertical, &[(inspector, 0.55), (layers, 0.45)]), side_width)]
        } else {
            vec![(inspector, side_width), (layers, side_width)]
        }
    };
    let side = side(&mut tiles);
    let sides: f32 = side.iter().map(|(_, w)| w).sum();
    let mut columns = vec![(outliner, outliner_width), (centre, (width - outliner_width - sides).max(200.0))];
    columns.extend(side);
    let root = linear(&mut tiles, LinearDir::Horizontal, &columns);
    egui_tiles::Tree::new(egui::Id::unique("bonescope-layout"), root, tiles)
}

/// A row or column of `children`, each with its share of the space.
fn linear(tiles: &mut Tiles<Pane>, dir: LinearDir, children: &[(TileId, f32)]) -> TileId {
    let mut container = Linear::new(dir, children.iter().map(|(id, _)| *id).collect());
    for &(id, share) in children {
        container.shares.set_share(id, share);
    }
    tiles.insert_container(Container::Linear(container))
}

/// The settings' arrangement, taken out of them for the frame (the panes borrow the settings): made for a window
/// `width` wide when there is none or it lacks a panel (one saved by an older version); each panel shown or hidden
/// as the settings say.
pub fn take_layout(settings: &mut Settings, width: f32) -> Layout {
    let complete = |layout: &Layout| Pane::ALL.iter().all(|pane| layout.tiles.find_pane(pane).is_some());
    let mut layout = settings.layout.take().filter(complete).unwrap_or_else(|| default_layout(width));
    for pane in Pane::ALL {
        let shown = pane.shown(settings);
        if let Some(tile) = layout.tiles.find_pane(&pane) {
            layout.tiles.set_visible(tile, shown);
        }
    }
    layout
}

/// What the tiles draw: each pane's panel on the shared state.
pub struct Panes<'p, 's> {
    pub shared: &'p mut Shared<'s>,
    pub outliner: &'p mut outliner::Outliner,
    pub inspector: &'p mut inspector::Inspector,
    pub plots: &'p mut plots::Plots,
    pub viewport: &'p mut viewport::Viewport,
    pub layers: &'p mut layers::LayersPanel,
    /// The window's style: each tile's `Ui` starts from the context's global style, not from the window's.
    pub style: std::sync::Arc<egui::Style>,
}

/// Space around a panel's contents (the viewport fills its tile).
const PANEL_MARGIN: i8 = 6;

impl egui_tiles::Behavior<Pane> for Panes<'_, '_> {
    fn pane_ui(&mut self, ui: &mut egui::Ui, _tile: TileId, pane: &mut Pane) -> UiResponse {
        let shared = &mut *self.shared;
        ui.set_style(self.style.clone());
        if *pane == Pane::Viewport {
            self.viewport.ui(ui, shared);
            return UiResponse::None;
        }
        egui::Frame::NONE.inner_margin(PANEL_MARGIN).show(ui, |ui| {
            ui.set_min_size(ui.available_size());
            match pane {
                Pane::Outliner => self.outliner.ui(ui, shared),
                Pane::Inspector => self.inspector.ui(ui, shared),
                Pane::Layers => self.layers.ui(ui, shared),
                Pane::Plots => self.plots.ui(ui, shared),
                Pane::Viewport => unreachable!("drawn above"),
            }
        });
        UiResponse::None
    }

    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().into()
    }

    /// Every panel has its tab, by which it is dragged elsewhere.
    fn simplification_options(&self) -> SimplificationOptions {
        SimplificationOptions { all_panes_must_have_tabs: true, ..SimplificationOptions::default() }
    }

    /// A panel is never made narrower than a readable column.
    fn min_size(&self) -> f32 {
        120.0
    }

    fn gap_width(&self, _style: &egui::Style) -> f32 {
        3.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui_tiles::Tile;

    fn columns(layout: &Layout) -> Vec<Vec<Pane>> {
        let root = layout.root().expect("a root");
        let Some(Tile::Container(container)) = layout.tiles.get(root) else { panic!("a container at the root") };
        container.children().map(|&child| panes_under(&layout.tiles, child)).collect()
    }

    fn panes_under(tiles: &Tiles<Pane>, tile: TileId) -> Vec<Pane> {
        match tiles.get(tile) {
            Some(Tile::Pane(pane)) => vec![*pane],
            Some(Tile::Container(container)) => {
                container.children().flat_map(|&child| panes_under(tiles, child)).collect()
            }
            None => Vec::new(),
        }
    }

    #[test]
    fn a_laptop_stacks_inspector_and_layers_and_a_wide_window_puts_them_side_by_side() {
        use Pane::*;
        assert_eq!(columns(&default_layout(1280.0)), [vec![Outliner], vec![Viewport, Plots], vec![Inspector, Layers]]);
        assert_eq!(
            columns(&default_layout(1920.0)),
            [vec![Outliner], vec![Viewport, Plots], vec![Inspector], vec![Layers]]
        );
    }

    #[test]
    fn a_saved_layout_lacking_a_panel_is_made_anew_and_hidden_panels_are_invisible() {
        let mut settings = Settings::default();
        let mut partial = default_layout(1280.0);
        let layers = partial.tiles.find_pane(&Pane::Layers).unwrap();
        partial.remove_recursively(layers);
        settings.layout = Some(partial);
        let layout = take_layout(&mut settings, 1280.0);
        assert!(Pane::ALL.iter().all(|pane| layout.tiles.find_pane(pane).is_some()));
        let layers = layout.tiles.find_pane(&Pane::Layers).unwrap();
        assert!(!layout.tiles.is_visible(layers), "the Layers panel starts hidden");
        settings.layout = Some(layout);
        settings.show_layers = true;
        let layout = take_layout(&mut settings, 1280.0);
        assert!(layout.tiles.is_visible(layers));
        settings.layout = Some(layout);
        let json = serde_json::to_string(&settings).unwrap();
        assert_eq!(serde_json::from_str::<Settings>(&json).unwrap(), settings, "the arrangement persists");
    }
}
