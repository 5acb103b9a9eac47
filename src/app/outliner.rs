//! The bone hierarchy as a tree with finding badges, a name filter, "only flagged", and each bone's inheritance
//! mode (right-click a bone to set it for the bone, its subtree or all bones). The nodes beside the figure (cameras,
//! lights, meshes' nodes, helpers) are listed apart, in a group collapsed at first.

use std::collections::HashSet;

use egui::{RichText, Sense, vec2};

use super::compared::LeftOut;
use super::document::ModeScope;
use super::pane::{Pane, Place, Visibility};
use super::panel::{Panel, Shared};
use super::text;
use crate::analysis::Findings;
use crate::model::{Choice, ModeChoice, NodeRole};
use crate::view::style::short_degrees;
use crate::view::{Badge, Palette};

#[derive(Default)]
pub struct Outliner {
    pub filter: String,
    pub only_flagged: bool,
    collapsed: HashSet<usize>,
    /// The inspected bone the list last showed: when another one is picked elsewhere (the viewport), the list
    /// scrolls to it.
    shown: Option<usize>,
}

const ROW_HEIGHT: f32 = 20.0;
const INDENT: f32 = 10.0;
/// The fold toggle's slot ("+" and "−" differ in width; a leaf keeps the slot empty): names line up by level.
const TOGGLE_WIDTH: f32 = 14.0;

impl Panel for Outliner {
    fn pane(&self) -> Pane {
        Pane::named("Skeleton")
    }

    fn place(&self) -> Place {
        Place::Left
    }

    fn visibility(&self) -> Visibility {
        Visibility::Always
    }

    fn ui(&mut self, ui: &mut egui::Ui, shared: &mut Shared) {
        // A narrow list puts "Only flagged" under the filter rather than past its edge (which would widen every
        // row below).
        ui.horizontal_wrapped(|ui| {
            let label = ui.label("Filter");
            let field = egui::TextEdit::singleline(&mut self.filter).hint_text("bone name").desired_width(120.0);
            ui.add(field).labelled_by(label.id);
            ui.checkbox(&mut self.only_flagged, "Only flagged");
        });
        legend(ui);
        self.others(ui, shared);
        ui.separator();
        let rows = self.visible_rows(shared);
        if rows.is_empty() {
            ui.label(RichText::new("no bone matches").weak());
        }
        let depths = shared.doc.rig.skeleton.depths();
        let mut list = egui::ScrollArea::vertical().auto_shrink([false, false]);
        let inspected = shared.selection.last().copied();
        if inspected != self.shown {
            self.shown = inspected;
            // Rows are drawn only when visible, so the list scrolls by row: the picked bone a few rows from the top.
            if let Some(row) = inspected.and_then(|bone| rows.iter().position(|&b| b == bone)) {
                list = list.vertical_scroll_offset(
                    (row.saturating_sub(3) as f32) * (ROW_HEIGHT + ui.spacing().item_spacing.y),
                );
            }
        }
        let step = indent_step(rows.iter().map(|&b| depths[b]).max().unwrap_or(0), ui.available_width());
        list.show_rows(ui, ROW_HEIGHT, rows.len(), |ui, range| {
            for &bone in &rows[range] {
                let depth = if self.filter.is_empty() { depths[bone] } else { 0 };
                self.row(ui, shared, bone, depth as f32 * step);
            }
        });
        // A bone picked in the list itself is in view already: the list stays where it is.
        if ui.ui_contains_pointer() && ui.input(|i| i.pointer.any_click()) {
            self.shown = shared.selection.last().copied();
        }
    }
}

impl Outliner {
    /// Findings now, or at any time of the clip when the analysis is there.
    fn flagged(shared: &Shared, bone: usize) -> bool {
        let now = shared.frame.primary.findings[bone].any();
        let ever = shared.results.analysis.as_ref().and_then(|a| a.scan.bones.get(bone)).is_some_and(|s| {
            s.stretched() || s.non_uniform_samples > 0 || s.mirrored_samples > 0 || s.degenerate_samples > 0
        });
        now || ever
    }

    /// The figure's bones the tree shows.
    fn visible_rows(&self, shared: &Shared) -> Vec<usize> {
        let skeleton = &shared.doc.rig.skeleton;
        let figure = skeleton.figure();
        let filter = self.filter.to_lowercase();
        let mut hidden = vec![false; skeleton.len()];
        let mut rows = Vec::new();
        for (bone, b) in skeleton.bones().iter().enumerate() {
            // Without a filter, collapsed bones hide their subtree.
            hidden[bone] = b.parent.is_some_and(|p| hidden[p] || self.collapsed.contains(&p));
            let matches = if filter.is_empty() { !hidden[bone] } else { b.name.to_lowercase().contains(&filter) };
            if figure[bone] && matches && (!self.only_flagged || Self::flagged(shared, bone)) {
                rows.push(bone);
            }
        }
        rows
    }

    /// The nodes that are not the figure's, by role, under a header collapsed at first: a file's cameras and
    /// helpers can outnumber its joints, and are seldom what it is opened for. The filters apply to them too.
    fn others(&mut self, ui: &mut egui::Ui, shared: &mut Shared) {
        let skeleton = &shared.doc.rig.skeleton;
        let figure = skeleton.figure();
        let filter = self.filter.to_lowercase();
        let others: Vec<(NodeRole, usize)> = (0..skeleton.len())
            .filter(|&b| !figure[b] && skeleton.bone(b).name.to_lowercase().contains(&filter))
            .filter(|&b| !self.only_flagged || Self::flagged(shared, b))
            .map(|b| (skeleton.bone(b).role, b))
            .collect();
        if others.is_empty() {
            return;
        }
        let header = egui::CollapsingHeader::new(format!("Cameras, lights and helpers ({})", others.len()))
            .id_salt("outliner-others")
            .default_open(false);
        header.show(ui, |ui| {
            let list = egui::ScrollArea::vertical().id_salt("outliner-others-list").max_height(ROW_HEIGHT * 8.0);
            list.show(ui, |ui| {
                for role in [NodeRole::Camera, NodeRole::Light, NodeRole::Mesh, NodeRole::Helper] {
                    let bones: Vec<usize> = others.iter().filter(|(r, _)| *r == role).map(|(_, b)| *b).collect();
                    if !bones.is_empty() {
                        ui.label(RichText::new(format!("{}s", role.label())).weak().small());
                    }
                    for bone in bones {
                        self.row(ui, shared, bone, 0.0);
                    }
                }
            });
        });
    }

    /// One bone's row, `indent` points in: the fold toggle, the badge, the name, the notes.
    fn row(&mut self, ui: &mut egui::Ui, shared: &mut Shared, bone: usize, indent: f32) {
        let skeleton = &shared.doc.rig.skeleton;
        let has_children = (bone + 1..skeleton.len()).any(|c| skeleton.parent(c) == Some(bone));
        let name = skeleton.bone(bone).shown_name().into_owned();
        let findings = shared.frame.primary.findings[bone];
        ui.horizontal(|ui| {
            ui.set_height(ROW_HEIGHT);
            ui.add_space(indent);
            // The slot is there in every row, a leaf's empty: names line up level by level.
            let (slot, _) = ui.allocate_exact_size(vec2(TOGGLE_WIDTH, ROW_HEIGHT), Sense::hover());
            if has_children {
                let collapsed = self.collapsed.contains(&bone);
                let toggle = ui.put(slot, egui::Button::new(if collapsed { "+" } else { "−" }).small().frame(false));
                if toggle.on_hover_text(format!("expand or collapse {name}")).clicked() && !self.collapsed.remove(&bone)
                {
                    self.collapsed.insert(bone);
                }
            }
            badge(ui, &findings);
            let font = egui::TextStyle::Button.resolve(ui.style());
            let name_needs = text::text_width(ui, &name, &font) + 2.0 * ui.spacing().button_padding.x;
            let notes = Notes::of(shared, bone).fitted(ui, ui.available_width() - name_needs);
            let name_width = ui.available_width() - notes.width(ui);
            let selected = shared.selection.contains(&bone);
            let path = || shared.doc.rig.skeleton.path(bone);
            let label = text::name_label(ui, &name, path, name_width, Some(selected));
            if label.clicked() {
                let extend = ui.input(|i| i.modifiers.command || i.modifiers.shift);
                shared.select(bone, extend);
            }
            // The menu works on the row it was opened on: that row is selected first.
            if label.secondary_clicked() && !selected {
                shared.select(bone, false);
            }
            label.context_menu(|ui| mode_menu(ui, shared, bone));
            notes.ui(ui, shared, bone);
        });
    }
}

/// Deep rows indent by at most this share of the list's width.
const MAX_INDENT_SHARE: f32 = 0.25;

/// The smallest step a level indents by, however deep the rig: a level must still read as one.
const MIN_INDENT: f32 = 4.0;

/// The indent of one level in a list `width` wide whose deepest row is `deepest` levels down: one step for every
/// level (so a chain reads as a staircase), [`INDENT`] where there is room, smaller where the deepest row would pass
/// [`MAX_INDENT_SHARE`] of the width.
fn indent_step(deepest: usize, width: f32) -> f32 {
    if deepest == 0 {
        return INDENT;
    }
    (MAX_INDENT_SHARE * width / deepest as f32).clamp(MIN_INDENT, INDENT)
}

/// What a row says after the name: the difference from a compared file, the mode, the worst shear. Measured before
/// the name is laid out, so that the name gets the rest of the row (shortened in the middle when it must).
struct Notes {
    difference: Option<RichText>,
    mode: Option<RichText>,
    worst: Option<RichText>,
}

impl Notes {
    fn of(shared: &Shared, bone: usize) -> Notes {
        let worst = stretched_summary(shared, bone).map(|summary| {
            RichText::new(format!("max {}°", short_degrees(summary.worst_shear_deg)))
                .small()
                .color(Badge::Stretched.color_for_shear(summary.worst_shear_deg))
        });
        Notes {
            difference: difference_text(shared, bone),
            mode: Some(RichText::new(shared.doc.modes()[bone].abbreviation()).weak().small()),
            worst,
        }
    }

    fn texts(&self) -> impl Iterator<Item = &RichText> {
        self.difference.iter().chain(&self.mode).chain(&self.worst)
    }

    /// The notes that leave the name whole in a row with `room` points beside the name: the name comes first, so
    /// the mode goes first (the Inspector and the menu show it), then the difference; the worst shear stays (the
    /// name shortens for it).
    fn fitted(mut self, ui: &egui::Ui, room: f32) -> Notes {
        if self.width(ui) > room {
            self.mode = None;
        }
        if self.width(ui) > room {
            self.difference = None;
        }
        self
    }

    fn width(&self, ui: &egui::Ui) -> f32 {
        let font = egui::TextStyle::Small.resolve(ui.style());
        let spacing = ui.spacing().item_spacing.x;
        self.texts().map(|text| text::text_width(ui, text.text(), &font) + spacing).sum::<f32>() + spacing
    }

    fn ui(self, ui: &mut egui::Ui, shared: &mut Shared, bone: usize) {
        if let Some(difference) = self.difference {
            ui.label(difference).on_hover_text(difference_hint(shared, bone));
        }
        if let Some(mode) = self.mode {
            // Part of the row: a click on it selects the bone, as one on the name does.
            let mode = ui.add(egui::Label::new(mode).sense(Sense::click()));
            if mode.on_hover_text(shared.doc.modes()[bone].description()).clicked() {
                let extend = ui.input(|i| i.modifiers.command || i.modifiers.shift);
                shared.select(bone, extend);
            }
        }
        if let (Some(worst), Some(summary)) = (self.worst, stretched_summary(shared, bone)) {
            let worst = ui.add(egui::Label::new(worst).sense(Sense::click())).on_hover_text(format!(
                "stretched in {} of {} samples, first at {}; worst shear {:.2}° at {} (click to go there)",
                summary.flagged_samples,
                shared.results.analysis.as_ref().map_or(0, |a| a.scan.samples),
                shared.time_text(summary.first_flagged_time.unwrap_or_default()),
                summary.worst_shear_deg,
                shared.time_text(summary.worst_shear_time)
            ));
            if worst.clicked() {
                let time = summary.worst_shear_time;
                shared.select(bone, false);
                *shared.playing = false;
                *shared.time = time;
            }
        }
    }
}

fn stretched_summary<'a>(shared: &Shared<'a>, bone: usize) -> Option<&'a crate::analysis::BoneSummary> {
    shared.results.analysis.as_ref().and_then(|a| a.scan.bones.get(bone)).filter(|s| s.stretched())
}

/// How far the compared file's partner of `bone` strays from it over the clip, when that is more than the threshold
/// (a percentage of the rig's size); a bone without a partner says so.
fn difference_text(shared: &Shared, bone: usize) -> Option<RichText> {
    let differences = shared.results.differences.as_ref()?;
    shared.doc.compared.as_ref()?;
    match differences.bones.get(bone).copied().flatten() {
        Some(fraction) if 100.0 * fraction > shared.settings.compare_threshold_percent => {
            // The ghost's colour: the badge says where the ghost parts from the pose.
            let color = Palette::new(shared.settings.dark).ghost.to_opaque();
            Some(RichText::new(format!("Δ {:.2}%", 100.0 * fraction)).small().color(color))
        }
        Some(_) => None,
        None => Some(RichText::new(left_out(shared, bone).map_or("unpaired", LeftOut::word)).small().weak()),
    }
}

fn difference_hint(shared: &Shared, bone: usize) -> String {
    let (Some(differences), Some(compared)) = (&shared.results.differences, &shared.doc.compared) else {
        return String::new();
    };
    let name = &shared.doc.rig.skeleton.bone(bone).name;
    match differences.bones.get(bone).copied().flatten() {
        Some(fraction) => format!(
            "{name} strays from its partner in {} by up to {:.3e} over the clip ({:.4} % of the rig's size; badged \
             above {} %, View → Thresholds)",
            compared.title(),
            fraction * differences.rig_size,
            100.0 * fraction,
            shared.settings.compare_threshold_percent,
        ),
        None => match left_out(shared, bone) {
            Some(why) => why.why().to_owned(),
            None => format!("no bone of this name in {}", compared.title()),
        },
    }
}

/// Why `bone` of the document is left out of the comparison, where it is.
fn left_out(shared: &Shared, bone: usize) -> Option<LeftOut> {
    shared.doc.compared.as_ref().and_then(|compared| compared.left_out.get(bone).copied().flatten())
}

/// The icon of a bone's most serious finding (every finding named on hover), in a slot of its own that every row
/// keeps: names stay where they are when findings come and go as the clip plays.
fn badge(ui: &mut egui::Ui, findings: &Findings) {
    let (rect, response) = ui.allocate_exact_size(vec2(BADGE_WIDTH, ROW_HEIGHT), Sense::hover());
    if let Some(badge) = Badge::primary(findings) {
        badge.paint_icon(ui.painter(), egui::pos2(rect.left() + 6.0, rect.center().y), 4.5);
        response.on_hover_text(Badge::of(findings).map(Badge::label).collect::<Vec<_>>().join(", "));
    }
}

/// The badge's slot.
const BADGE_WIDTH: f32 = 12.0;

/// The room an icon takes before its name in the legend.
const ICON_WIDTH: f32 = 14.0;

/// Colours and icons, explained once at the top of the list.
fn legend(ui: &mut egui::Ui) {
    ui.horizontal_wrapped(|ui| {
        let font = egui::TextStyle::Small.resolve(ui.style());
        for badge in Badge::ALL {
            // Icon and name as one item of a known size, so that a row too short for it wraps before it.
            let galley = ui.painter().layout_no_wrap(badge.label().to_owned(), font.clone(), ui.visuals().text_color());
            let size = vec2(ICON_WIDTH + galley.size().x, galley.size().y.max(14.0));
            let (rect, response) = ui.allocate_exact_size(size, Sense::hover());
            badge.paint_icon(ui.painter(), egui::pos2(rect.left() + 6.0, rect.center().y), 4.5);
            let text_at = egui::pos2(rect.left() + ICON_WIDTH, rect.center().y - galley.size().y / 2.0);
            ui.painter().galley(text_at, galley, ui.visuals().text_color());
            response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Label, true, badge.label()));
            response.on_hover_text(badge.explanation());
        }
    });
}

/// Sets a mode (or the declared ones) for the bone, its subtree or all bones; each list marks what its scope has.
fn mode_menu(ui: &mut egui::Ui, shared: &mut Shared, bone: usize) {
    for (scope, title) in [
        (ModeScope::Bone, "Set mode of this bone"),
        (ModeScope::Subtree, "Set mode of its subtree"),
        (ModeScope::All, "Set mode of all bones"),
    ] {
        ui.menu_button(title, |ui| {
            let current = shared.doc.current_choice(bone, scope);
            for &choice in ModeChoice::ALL {
                let marked = ui.selectable_label(current == Some(choice), choice.id());
                if marked.on_hover_text(choice.description()).clicked() {
                    shared.doc.set_mode(bone, scope, choice);
                    ui.close();
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_level_indents_by_one_step_within_a_share_of_the_list() {
        assert_eq!(indent_step(3, 600.0), INDENT, "room enough: the whole step");
        assert_eq!(indent_step(0, 180.0), INDENT);
        let step = indent_step(12, 270.0);
        assert!(step < INDENT && 12.0 * step <= MAX_INDENT_SHARE * 270.0 + 1e-3, "{step}");
        assert_eq!(indent_step(200, 270.0), MIN_INDENT, "a level still reads as one");
    }
}
