//! The menu bar and the toolbar: files, undo and redo, the view, the animation, the inheritance mode of every bone,
//! the ghost, and the units of a comparison.

use std::path::PathBuf;
use std::sync::Arc;

use egui::{Key, KeyboardShortcut, Modifiers, RichText};

use super::compared::Compared;
use super::document::{Document, Ghost, ModeScope};
use super::pane::{Pane, Visibility};
use super::panel::Shared;
use super::stance::Stance;
use super::text;
use crate::analysis::Tolerances;
use crate::eval::SkinningMethod;
use crate::eval::layers::RotationInterpolation;
use crate::model::{Choice, ModeChoice, Unit, UpAxis};
use crate::view::Badge;

/// What the menus and keys ask of the session after the frame (things that replace or step the document).
#[derive(Debug, Default)]
pub struct Actions {
    pub open_dialog: bool,
    /// File → Compare with…
    pub compare_dialog: bool,
    pub stop_comparing: bool,
    pub open: Option<PathBuf>,
    pub compare: Option<PathBuf>,
    pub open_demo: bool,
    pub frame_all: bool,
    pub undo: bool,
    pub redo: bool,
    /// The document's edit this frame takes the place of the history's current step (a fix tried instead of the
    /// one tried): an undo goes back to the state before both.
    pub step_in_place: bool,
}

/// What the menus list that the panels' shared state does not hold: the steps the Edit menu undoes and redoes, and
/// the panels the View menu shows and hides.
pub struct Menus {
    pub undo: Option<String>,
    pub redo: Option<String>,
    /// Every step of the history, oldest first, and the one the document is in.
    pub history: Vec<String>,
    pub current: usize,
    pub panels: Vec<(Pane, Visibility)>,
}

const UNDO: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
const REDO: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::Z);
const REDO_Y: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);

/// Ctrl+Z undoes, Ctrl+Shift+Z and Ctrl+Y redo (⌘ on a Mac).
pub fn history_keys(ctx: &egui::Context, actions: &mut Actions) {
    // Ctrl+Z also matches Ctrl+Shift+Z (shift is not told apart): redo is looked for first.
    ctx.input_mut(|i| {
        actions.redo |= i.consume_shortcut(&REDO) || i.consume_shortcut(&REDO_Y);
        actions.undo |= i.consume_shortcut(&UNDO);
    });
}

pub fn ui(ui: &mut egui::Ui, shared: &mut Shared, menus: &Menus, actions: &mut Actions) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| file_menu(ui, shared, actions));
        ui.menu_button("Edit", |ui| edit_menu(ui, menus, actions));
        ui.menu_button("View", |ui| view_menu(ui, shared, menus, actions));
        ui.separator();
        ui.label(RichText::new(shared.doc.title()).strong());
        // The pickers of a file's unit and axis have their place beside its name, so the toolbar below never moves
        // for them.
        up_of_document(ui, shared.doc, actions);
        unit_pickers(ui, shared.doc);
    });
    // On a narrow window the pickers wrap onto a second row rather than run off the edge.
    ui.horizontal_wrapped(|ui| {
        clip_picker(ui, shared);
        ui.separator();
        mode_picker(ui, shared);
        ui.separator();
        ghost_picker(ui, shared);
        ui.separator();
        // Greyed, not gone, on a file without a skin: the controls after it stay where they are.
        let skinned = !shared.doc.rig.skins.is_empty();
        ui.add_enabled_ui(skinned, |ui| skinning_picker(ui, shared))
            .response
            .on_disabled_hover_text("no skinned mesh in the file");
        ui.separator();
        if let Some((pane, visibility)) = menus.panels.iter().find(|(pane, _)| *pane == Pane::LAYERS) {
            let mut shown = shared.settings.shows(pane, *visibility);
            let hint = "blend, additive, crossfade, shake, targets, interpolation, bind pose, storage";
            if ui.toggle_value(&mut shown, pane.title()).on_hover_text(hint).changed() {
                shared.settings.show(pane, shown);
            }
        }
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
    rotation_menu(ui, shared.doc);
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
            (
                "min non-uniform",
                "a bone not stretched is non-uniform when max/min of its scale factors exceeds 1 + this",
                &mut tolerances.min_non_uniform,
                1.0,
                "",
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
        *compare_percent = super::settings::Settings::default().compare_threshold_percent;
    }
}

/// Undo and Redo, each saying what it undoes or redoes, with its keys.
fn edit_menu(ui: &mut egui::Ui, menus: &Menus, actions: &mut Actions) {
    for (step, name, shortcut, asked) in
        [(&menus.undo, "Undo", UNDO, &mut actions.undo), (&menus.redo, "Redo", REDO, &mut actions.redo)]
    {
        let text = step.as_ref().map_or_else(|| name.to_owned(), |label| format!("{name} {}", text::drawable(label)));
        let button = egui::Button::new(text).shortcut_text(ui.ctx().format_shortcut(&shortcut));
        if ui.add_enabled(step.is_some(), button).clicked() {
            *asked = true;
        }
    }
    ui.menu_button("History", |ui| history_list(ui, menus));
}

/// The steps of the history, oldest first: the one the document is in marked, those undone greyed.
fn history_list(ui: &mut egui::Ui, menus: &Menus) {
    for (i, label) in menus.history.iter().enumerate() {
        let text = if label.is_empty() { "opened".to_owned() } else { text::drawable(label) };
        let text = match i.cmp(&menus.current) {
            std::cmp::Ordering::Less => RichText::new(text),
            std::cmp::Ordering::Equal => RichText::new(text).strong(),
            std::cmp::Ordering::Greater => RichText::new(text).weak(),
        };
        let hint = if i > menus.current { "undone: Redo takes it again" } else { "a step of the history" };
        ui.label(text).on_hover_text(hint);
    }
}

fn view_menu(ui: &mut egui::Ui, shared: &mut Shared, menus: &Menus, actions: &mut Actions) {
    ui.checkbox(&mut shared.settings.dark, "Dark theme");
    for (pane, visibility) in menus.panels.iter().filter(|(_, v)| *v != Visibility::Always) {
        let mut shown = shared.settings.shows(pane, *visibility);
        if ui.checkbox(&mut shown, pane.title()).changed() {
            shared.settings.show(pane, shown);
        }
    }
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

/// The width of the top bar's lists, in points: the animation's too, whatever its name's length (shortened to fit),
/// so the controls after it never move; the ghost's longest choice ("cmu_12_01_walk.bvh") fits, and the bar does
/// not wrap in a window 1000 points wide.
const PICKER_WIDTH: f32 = 160.0;

fn clip_picker(ui: &mut egui::Ui, shared: &mut Shared) {
    let label = ui.label("Animation");
    let clips = &shared.doc.rig.clips;
    let current = shared.doc.clip().map_or_else(|| "rest pose".to_owned(), |c| c.label());
    // A take's name can be a path long: shortened in the middle, whole on hover and in the list.
    let font = egui::TextStyle::Button.resolve(ui.style());
    let spacing = ui.spacing();
    let room = PICKER_WIDTH - spacing.icon_width - spacing.item_spacing.x - 2.0 * spacing.button_padding.x;
    let shown = text::shorten_middle(&current, |t| text::text_width(ui, t, &font) <= room);
    let mut chosen = shared.doc.setup().clip;
    egui::ComboBox::from_id_salt("animation")
        .selected_text(shown)
        .width(PICKER_WIDTH)
        .show_ui(ui, |ui| {
            for clip in clips {
                ui.selectable_value(&mut chosen, Some(clip.index), text::clip_choice(clip));
            }
            ui.selectable_value(&mut chosen, None, "rest pose");
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(current);
    if chosen != shared.doc.setup().clip {
        // Only the rig's clips are listed. The window keeps the time within the new clip's span.
        let _ = shared.doc.set_clip(chosen);
    }
}

/// The mode of every bone at once, or each bone's declared one (per-bone edits live in the outliner).
fn mode_picker(ui: &mut egui::Ui, shared: &mut Shared) {
    let label = ui.label("Inherit scale");
    let current = shared.doc.current_choice(0, ModeScope::All);
    let mut chosen = None;
    egui::ComboBox::from_id_salt("inherit-all")
        .selected_text(current.map_or("mixed", ModeChoice::id))
        .width(PICKER_WIDTH)
        // Every choice in view (ten: egui's default height shows eight).
        .height(f32::INFINITY)
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
        .width(PICKER_WIDTH)
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

/// Beside the document's name, where its file states no axes (a BVH) or lies down in the view, the axis it stands
/// along; standing it up frames it again.
fn up_of_document(ui: &mut egui::Ui, doc: &mut Document, actions: &mut Actions) {
    // A file that states no unit (a BVH) states no axes either.
    if doc.stance.pickable(doc.rig.unit.is_some())
        && let Some(up) = up_picker(ui, &doc.title(), doc.stance, "the view")
    {
        *doc = doc.stood_up(up);
        actions.frame_all = true;
    }
}

/// Beside the document's name, for each file of the comparison that states no unit (a BVH), the unit it is in, and for
/// the compared file the axis it stands along where it states none or lies down beside the document: the ghost, the
/// dashed curves and the differences follow them.
fn unit_pickers(ui: &mut egui::Ui, doc: &mut Document) {
    let Some(compared) = doc.compared.clone() else { return };
    ui.separator();
    if !compared.states_unit()
        && let Some(unit) = unit_picker(ui, &compared.title(), compared.rig.unit, &doc.title())
    {
        replace(doc, compared.given_unit(unit));
    }
    if compared.stance.pickable(compared.states_unit())
        && let Some(up) = up_picker(ui, &compared.title(), compared.stance, &doc.title())
    {
        replace(doc, compared.given_up(up, &doc.rig));
    }
    if doc.rig.unit.is_none()
        && let Some(unit) = unit_picker(ui, &doc.title(), compared.units()[0], &compared.title())
    {
        replace(doc, compared.in_document_unit(unit));
    }
}

/// File → "Play compared rotations by" while comparing: how the compared file's rotation keys are played, to see
/// a bake as Blender, Unity or Unreal (nlerp) will show it.
fn rotation_menu(ui: &mut egui::Ui, doc: &mut Document) {
    let Some(compared) = doc.compared.clone() else { return };
    ui.menu_button("Play compared rotations by", |ui| {
        for &played in RotationInterpolation::ALL {
            let chosen =
                ui.selectable_label(played == compared.played, played.id()).on_hover_text(played.description());
            if chosen.clicked() && played != compared.played {
                replace(doc, compared.played_by(played));
            }
        }
    });
}

/// A picker of the unit `file` is in (`unit`, `None` while not given); the unit picked, if another.
fn unit_picker(ui: &mut egui::Ui, file: &str, unit: Option<Unit>, other: &str) -> Option<Unit> {
    let label = ui.label(format!("unit of {file}"));
    let mut picked = unit;
    egui::ComboBox::from_id_salt(("unit", file))
        .selected_text(unit.map_or_else(|| "not stated".to_owned(), |u| u.to_string()))
        .show_ui(ui, |ui| {
            for named in Unit::named() {
                ui.selectable_value(&mut picked, Some(named), named.to_string());
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(format!("{file} states no unit: the one it is in, to compare it with {other} in one unit"));
    picked.filter(|_| picked != unit)
}

/// A picker of the axis `file` stands along (its `stance`), saying where it lies down beside `beside`; the axis
/// picked, if another.
fn up_picker(ui: &mut egui::Ui, file: &str, stance: Stance, beside: &str) -> Option<UpAxis> {
    let label = ui.label(format!("up of {file}"));
    let mut picked = stance.up;
    egui::ComboBox::from_id_salt(("up", file))
        .selected_text(stance.up.id().to_uppercase())
        .show_ui(ui, |ui| {
            for &up in UpAxis::ALL {
                ui.selectable_value(&mut picked, up, up.id().to_uppercase()).on_hover_text(up.description());
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text(format!("the axis {file}'s skeleton stands along, where the file does not say (BVH)"));
    if let Some([ours, theirs]) = stance.apart {
        let text =
            format!("lies along {}: {beside} stands along {}", theirs.id().to_uppercase(), ours.id().to_uppercase());
        ui.label(RichText::new(text).color(Badge::NonUniform.color()))
            .on_hover_text("every difference would measure the turn: pick the axis the file stands along");
    }
    (picked != stance.up).then_some(picked)
}

/// The document compared with `compared` instead.
fn replace(doc: &mut Document, compared: Compared) {
    doc.compared = Some(Arc::new(compared));
}
