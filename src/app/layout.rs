//! The panels as tiles: the user tabs, splits, drags (by the tab) and resizes them, and the arrangement persists
//! with the settings. The first arrangement fits the window's width: below [`WIDE`] the Inspector and the Layers
//! share one column, one above the other, so that each keeps the width its numbers need; wider, each has its own.

use egui_tiles::{Container, Linear, LinearDir, SimplificationOptions, TileId, Tiles, UiResponse};

use super::pane::{Layout, Pane, Place};
use super::panel::{Panel, Shared};
use super::settings::Settings;
use super::viewport::Viewport;

/// From this window width (points) on, the Inspector and the Layers stand side by side.
pub const WIDE: f32 = 1600.0;

/// The widths the side panels start with, in points: the skeleton's names and the inspector's four matrix columns.
const OUTLINER_WIDTH: f32 = 280.0;
const SIDE_WIDTH: f32 = 340.0;

/// The first arrangement of `panels` (each with where it goes) for a window `width` points wide: the left column,
/// the centre one (the viewport over the plots), and the right-hand panels stacked in one column or, from [`WIDE`]
/// on, side by side.
pub fn default_layout(width: f32, panels: &[(Pane, Place)]) -> Layout {
    // A small window gives each side a share instead, so that the viewport keeps over 40 % of it.
    let (outliner_width, side_width) = (OUTLINER_WIDTH.min(0.22 * width), SIDE_WIDTH.min(0.32 * width));
    let mut tiles = Tiles::default();
    let (mut left, mut centre, mut right) = (Vec::new(), Vec::new(), Vec::new());
    for (pane, place) in panels {
        let tile = tiles.insert_pane(pane.clone());
        match *place {
            Place::Left => left.push((tile, 1.0)),
            Place::Centre(share) => centre.push((tile, share)),
            Place::Right(share) => right.push((tile, share)),
        }
    }
    let left = linear(&mut tiles, LinearDir::Vertical, &left);
    let centre = linear(&mut tiles, LinearDir::Vertical, &centre);
    let side = if width < WIDE {
        vec![(linear(&mut tiles, LinearDir::Vertical, &right), side_width)]
    } else {
        right.iter().map(|&(tile, _)| (tile, side_width)).collect()
    };
    let sides: f32 = side.iter().map(|(_, w)| w).sum();
    let mut columns = vec![(left, outliner_width), (centre, (width - outliner_width - sides).max(200.0))];
    columns.extend(side);
    let root = linear(&mut tiles, LinearDir::Horizontal, &columns);
    egui_tiles::Tree::new(egui::Id::unique("bonescope-layout"), root, tiles)
}

/// A row or column of `children`, each with its share of the space (one child is itself).
fn linear(tiles: &mut Tiles<Pane>, dir: LinearDir, children: &[(TileId, f32)]) -> TileId {
    if let [(only, _)] = children {
        return *only;
    }
    let mut container = Linear::new(dir, children.iter().map(|(id, _)| *id).collect());
    for &(id, share) in children {
        container.shares.set_share(id, share);
    }
    tiles.insert_container(Container::Linear(container))
}

/// The settings' arrangement of `panels`, taken out of them for the frame (the panes borrow the settings): made for
/// a window `width` wide when there is none or it is not of these panels (one saved by another version); each panel
/// shown or hidden as the settings say.
pub fn take_layout(settings: &mut Settings, width: f32, panels: &[&dyn Panel]) -> Layout {
    let places: Vec<(Pane, Place)> = panels.iter().map(|p| (p.pane(), p.place())).collect();
    let ours = |layout: &Layout| {
        let panes = layout.tiles.tiles().filter_map(|t| match t {
            egui_tiles::Tile::Pane(pane) => Some(pane),
            egui_tiles::Tile::Container(_) => None,
        });
        panes.count() == places.len() && places.iter().all(|(pane, _)| layout.tiles.find_pane(pane).is_some())
    };
    let mut layout = settings.layout.take().filter(ours).unwrap_or_else(|| default_layout(width, &places));
    for panel in panels {
        let pane = panel.pane();
        let shown = settings.shows(&pane, panel.visibility());
        if let Some(tile) = layout.tiles.find_pane(&pane) {
            layout.tiles.set_visible(tile, shown);
        }
    }
    layout
}

/// What the tiles draw: each pane's panel on the shared state.
pub struct Panes<'p, 's> {
    pub shared: &'p mut Shared<'s>,
    pub viewport: &'p mut Viewport,
    pub panels: &'p mut [Box<dyn Panel>],
    /// The window's style: each tile's `Ui` starts from the context's global style, not from the window's.
    pub style: std::sync::Arc<egui::Style>,
}

/// How far either side of the gap between two panels a press grabs it to resize them: more than egui's 3 points
/// either side of a panel's edge, whose neighbours (the viewport's orbit, a tab's drag) would take a press 4 points
/// away.
pub const GRAB_RADIUS: f32 = 4.0;

/// Space around a panel's contents (the viewport fills its tile).
const PANEL_MARGIN: i8 = 6;

impl egui_tiles::Behavior<Pane> for Panes<'_, '_> {
    fn pane_ui(&mut self, ui: &mut egui::Ui, _tile: TileId, pane: &mut Pane) -> UiResponse {
        let shared = &mut *self.shared;
        ui.set_style(self.style.clone());
        if *pane == Pane::VIEWPORT {
            self.viewport.ui(ui, shared);
            return UiResponse::None;
        }
        let Some(panel) = self.panels.iter_mut().find(|p| p.pane() == *pane) else { return UiResponse::None };
        egui::Frame::NONE.inner_margin(PANEL_MARGIN).show(ui, |ui| {
            ui.set_min_size(ui.available_size());
            panel.ui(ui, shared);
        });
        UiResponse::None
    }

    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().to_owned().into()
    }

    /// Every panel has its tab, by which it is dragged elsewhere.
    fn simplification_options(&self) -> SimplificationOptions {
        SimplificationOptions { all_panes_must_have_tabs: true, ..SimplificationOptions::default() }
    }

    /// A panel is never made narrower than a readable column.
    fn min_size(&self) -> f32 {
        120.0
    }

    /// The whole gap resizes ([`GRAB_RADIUS`] either side of its middle), and no panel's contents (the viewport's
    /// orbit, a tab's drag) reach into it.
    fn gap_width(&self, _style: &egui::Style) -> f32 {
        2.0 * GRAB_RADIUS
    }

    /// A thin line down the middle of the gap, as egui draws a panel's edge, brighter while grabbed.
    fn resize_stroke(&self, style: &egui::Style, state: egui_tiles::ResizeState) -> egui::Stroke {
        match state {
            egui_tiles::ResizeState::Idle => style.visuals.widgets.noninteractive.bg_stroke,
            egui_tiles::ResizeState::Hovering => style.visuals.widgets.hovered.fg_stroke,
            egui_tiles::ResizeState::Dragging => style.visuals.widgets.active.fg_stroke,
        }
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
            Some(Tile::Pane(pane)) => vec![pane.clone()],
            Some(Tile::Container(container)) => {
                container.children().flat_map(|&child| panes_under(tiles, child)).collect()
            }
            None => Vec::new(),
        }
    }

    fn panels() -> Vec<Box<dyn Panel>> {
        let mut panels: Vec<Box<dyn Panel>> = vec![Box::new(Viewport::default())];
        panels.extend(crate::app::window::panels());
        panels
    }

    fn places() -> Vec<(Pane, Place)> {
        panels().iter().map(|p| (p.pane(), p.place())).collect()
    }

    #[test]
    fn a_laptop_stacks_inspector_and_layers_and_a_wide_window_puts_them_side_by_side() {
        let [viewport, outliner, inspector, layers, plots] =
            ["Viewport", "Skeleton", "Inspector", "Layers", "Plots"].map(Pane::named);
        assert_eq!(
            columns(&default_layout(1280.0, &places())),
            [vec![outliner.clone()], vec![viewport.clone(), plots.clone()], vec![inspector.clone(), layers.clone()]]
        );
        assert_eq!(
            columns(&default_layout(1920.0, &places())),
            [vec![outliner], vec![viewport, plots], vec![inspector], vec![layers]]
        );
    }

    #[test]
    fn a_saved_layout_lacking_a_panel_is_made_anew_and_hidden_panels_are_invisible() {
        let panels = panels();
        let panels: Vec<&dyn Panel> = panels.iter().map(|p| p.as_ref()).collect();
        let mut settings = Settings::default();
        let mut partial = default_layout(1280.0, &places());
        let layers = partial.tiles.find_pane(&Pane::LAYERS).unwrap();
        partial.remove_recursively(layers);
        settings.layout = Some(partial);
        let layout = take_layout(&mut settings, 1280.0, &panels);
        assert!(places().iter().all(|(pane, _)| layout.tiles.find_pane(pane).is_some()));
        let layers = layout.tiles.find_pane(&Pane::LAYERS).unwrap();
        assert!(!layout.tiles.is_visible(layers), "the Layers panel starts hidden");
        settings.layout = Some(layout);
        settings.show(&Pane::LAYERS, true);
        let layout = take_layout(&mut settings, 1280.0, &panels);
        assert!(layout.tiles.is_visible(layers));
        settings.layout = Some(layout);
        let json = serde_json::to_string(&settings).unwrap();
        assert_eq!(serde_json::from_str::<Settings>(&json).unwrap(), settings, "the arrangement persists");
    }
}
