//! The menu bar and the toolbar: files, the animation, the inheritance mode of every bone, the ghost mode.

use std::path::PathBuf;

use egui::RichText;

use super::{Ghost, ModeChoice, ModeScope, Shared, text};
use crate::analysis::Tolerances;
use crate::eval::SkinningMethod;
use crate::model::Choice;

/// What the toolbar asks the app to do after the frame (things that replace the document).
#[derive(Default)]
pub struct Actions {
    pub open_dialog: bool,
    /// File → Compare with…
    pub compare_dialog: bool,
    pub stop_comparing: bool,
    pub open: Option<PathBuf>,
    pub open_demo: bool,
    pub frame_all: bool,
    pub clip_changed: bool,
}

pub fn ui(ui: &mut egui::Ui, shared: &mut Shared, actions: &mut Actions) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| file_menu(ui, shared, actions));
        ui.menu_button("View", |ui| view_menu(ui, shared, actions));
        ui.separator();
        ui.label(RichText::new(shared.doc.title()).strong());
    });
    // On a narrow window the pickers wrap onto a second row rather than run off the edge.
    ui.horizontal_wrapped(|ui| {
        clip_picker(ui, shared, actions);
        ui.separator();
        mode_picker(ui, shared);
        ui.separator();
        ghost_picker(ui, shared);
        super::compare::unit_pickers(ui, shared.doc);
        ui.separator();
        if !shared.doc.rig.skins.is_empty() {
            skinning_picker(ui, shared);
            ui.separator();
        }
        ui.toggle_value(&mut shared.settings.show_layers, "Layers")
            .on_hover_text("blend, additive, crossfade, shake, targets, interpolation, bind pose, storage");
    });
}

fn file_menu(ui: &mut egui::Ui, shared: &mut Shared, actions: &mut Actions) {
    if ui.button("Open…").clicked() {
        actions.open_dialog = true;
    }
    if ui.button("Open demo rig").clicked() {
        actions.open_demo = true;
    }
    ui.menu_button("Open recent", |ui| {
        if shared.settings.recent.is_empty() {
            ui.label("no recent files");
        }
        for path in &shared.settings.recent {
            if ui.button(path.display().to_string()).clicked() {
                actions.open = Some(path.clone());
            }
        }
    });
    ui.separator();
    let hint = "load a second file (an export, a bake) as the ghost: bones paired by name, its curves dashed";
    if ui.button("Compare with…").on_hover_text(hint).clicked() {
        actions.compare_dialog = true;
    }
    if let Some(compared) = &shared.doc.compared
        && ui.button(format!("Stop comparing with {}", compared.title())).clicked()
    {
        actions.stop_comparing = true;
    }
    super::compare::rotation_menu(ui, shared.doc);
    ui.separator();
    if ui.button("Quit").clicked() {
        ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

/// The verdicts' thresholds (persisted with the settings; README, "What the verdicts mean"), and the compared file's.
fn thresholds(ui: &mut egui::Ui, tolerances: &mut Tolerances, compare_percent: &mut f64) {
    egui::Grid::new("thresholds").num_columns(2).show(ui, |ui| {
        let rows = [
            (
                "min anisotropy",
                "scale factors differ when max/min exceeds 1 + this",
                &mut tolerances.min_anisotropy,
                1.0,
                "",
            ),
            (
                "min stretch angle",
                "the stretch rotation U must turn by more than this",
                &mut tolerances.min_stretch_deg,
                90.0,
                "°",
            ),
            (
                "min shear angle",
                "a stretched bone must shear by more than this",
                &mut tolerances.min_shear_deg,
                90.0,
                "°",
            ),
        ];
        let compared = (
            "compared file",
            "badge bones farther than this from their partner in a compared file, in % of the rig's size",
            &mut *compare_percent,
            100.0,
            " %",
        );
        for (name, hint, value, max, suffix) in rows.into_iter().chain([compared]) {
            ui.label(name).on_hover_text(hint);
            let field = egui::DragValue::new(value).range(0.0..=max).speed(max * 1e-5).max_decimals(6).suffix(suffix);
            let field = ui.add(field).on_hover_text(hint);
            field.widget_info(|| egui::WidgetInfo::labeled(egui::Role::SpinButton, true, name));
            ui.end_row();
        }
    });
    if ui.button("Defaults").clicked() {
        *tolerances = Tolerances::default();
        *compare_percent = crate::app::Settings::default().compare_threshold_percent;
    }
}

fn view_menu(ui: &mut egui::Ui, shared: &mut Shared, actions: &mut Actions) {
    ui.checkbox(&mut shared.settings.dark, "Dark theme");
    ui.checkbox(&mut shared.settings.show_plots, "Plots");
    ui.checkbox(&mut shared.settings.show_inspector, "Inspector");
    ui.checkbox(&mut shared.settings.show_layers, "Layers");
    // Editing a number is a click inside the menu: it stays open until a click outside.
    let config =
        egui::containers::menu::MenuConfig::new().close_behavior(egui::PopupCloseBehavior::CloseOnClickOutside);
    egui::containers::menu::SubMenuButton::new("Thresholds")
        .config(config)
        .ui(ui, |ui| thresholds(ui, &mut shared.settings.tolerances, &mut shared.settings.compare_threshold_percent));
    if ui.button("Frame all").clicked() {
        actions.frame_all = true;
    }
    if ui.button("Reset the panels").on_hover_text("the arrangement made for this window's width").clicked() {
        shared.settings.layout = None;
    }
}

/// The widest the animation's name is shown in the toolbar, in points.
const CLIP_NAME_WIDTH: f32 = 160.0;

fn clip_picker(ui: &mut egui::Ui, shared: &mut Shared, actions: &mut Actions) {
    let label = ui.label("Animation");
    let clips = &shared.doc.rig.clips;
    let current = shared.doc.clip().map_or_else(|| "rest pose".to_owned(), |c| c.label());
    // A take's name can be a path long: shortened in the middle, whole on hover and in the list.
    let font = egui::TextStyle::Button.resolve(ui.style());
    let shown = text::shorten_middle(&current, |t| text::text_width(ui, t, &font) <= CLIP_NAME_WIDTH);
    let mut chosen = shared.doc.setup().clip;
    egui::ComboBox::from_id_salt("animation")
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for clip in clips {
                ui.selectable_value(
                    &mut chosen,
                    Some(clip.index),
                    format!("{} ({:.2} s)", clip.label(), clip.duration()),
                );
            }
            ui.selectable_value(&mut chosen, None, "rest pose");
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(current);
    if chosen != shared.doc.setup().clip && shared.doc.set_clip(chosen).is_ok() {
        actions.clip_changed = true;
    }
}

/// The mode of every bone at once, or each bone's declared one (per-bone edits live in the outliner).
fn mode_picker(ui: &mut egui::Ui, shared: &mut Shared) {
    let label = ui.label("Inherit scale");
    let current = shared.doc.current_choice(0, ModeScope::All);
    let mut chosen = None;
    egui::ComboBox::from_id_salt("inherit-all")
        .selected_text(current.map_or("mixed", ModeChoice::id))
        .width(170.0)
        .show_ui(ui, |ui| {
            for &choice in ModeChoice::ALL {
                if ui
                    .selectable_label(current == Some(choice), choice.id())
                    .on_hover_text(choice.description())
                    .clicked()
                {
                    chosen = Some(choice);
                }
            }
        })
        .response
        .labelled_by(label.id);
    if let Some(choice) = chosen {
        shared.doc.set_mode(0, ModeScope::All, choice);
    }
}

fn skinning_picker(ui: &mut egui::Ui, shared: &mut Shared) {
    let label = ui.label("Skinning");
    let skinning = &mut shared.settings.scene.skinning;
    egui::ComboBox::from_id_salt("skinning")
        .selected_text(skinning.label())
        .show_ui(ui, |ui| {
            for &method in SkinningMethod::ALL {
                ui.selectable_value(skinning, method, method.label());
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text("how meshes are skinned: as the file declares, or one method everywhere (engines differ)");
}

fn ghost_picker(ui: &mut egui::Ui, shared: &mut Shared) {
    let label = ui.label("Ghost");
    let text = shared.doc.ghost.as_ref().map_or("off", Ghost::label);
    egui::ComboBox::from_id_salt("ghost")
        .selected_text(text)
        .width(170.0)
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut shared.doc.ghost, None, "off");
            if let Some(compared) = &shared.doc.compared {
                let hint = format!("{}, bones paired by name", compared.path.display());
                let label = Ghost::Compared.label();
                ui.selectable_value(&mut shared.doc.ghost, Some(Ghost::Compared), label).on_hover_text(hint);
            }
            if !shared.doc.layers().is_empty() {
                ui.selectable_value(&mut shared.doc.ghost, Some(Ghost::Unlayered), Ghost::Unlayered.label())
                    .on_hover_text("the clip as authored, without the layers");
            }
            for &choice in ModeChoice::ALL {
                ui.selectable_value(&mut shared.doc.ghost, Some(Ghost::Modes(choice)), choice.id())
                    .on_hover_text(choice.description());
            }
        })
        .response
        .labelled_by(label.id);
}
