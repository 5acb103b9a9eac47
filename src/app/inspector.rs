//! The selected bone at the current time: local and model matrices, every decomposed part, the findings, why it
//! shears (the Why? section), the morph-target weights of the meshes it carries, and a button that copies the same
//! JSON `bonescope inspect` prints.

use egui::{Grid, RichText, Ui};
use glam::DMat4;

use super::pane::{Pane, Place};
use super::panel::{Panel, Shared};
use super::text::{compact, precise};
use super::why;
use crate::analysis::report::{BoneReport, LayeredInspectReport, SampleReport};
use crate::math::AffineParts;
use crate::model::Choice;
use crate::view::Badge;

/// The panel: the shared state's bone, and what its Why? section keeps between frames.
#[derive(Default)]
pub struct Inspector {
    why: why::Memory,
}

impl Panel for Inspector {
    fn pane(&self) -> Pane {
        Pane::named("Inspector")
    }

    fn place(&self) -> Place {
        Place::Right(0.55)
    }

    fn ui(&mut self, ui: &mut Ui, shared: &mut Shared) {
        let Some(bone) = why::shown(shared, &mut self.why) else {
            ui.label(RichText::new("Select a bone in the viewport or the list.").weak());
            return;
        };
        why::pinned_line(ui, shared, bone);
        bone_ui(ui, shared, &mut self.why, bone);
    }
}

fn bone_ui(ui: &mut Ui, shared: &mut Shared, why: &mut why::Memory, bone: usize) {
    let reports =
        BoneReport::all(&shared.doc.rig.skeleton, shared.doc.modes(), &shared.frame.pose, &shared.settings.tolerances);
    let report = &reports[bone];
    ui.label(RichText::new(&report.name).strong().size(16.0));
    ui.label(format!("bone {} · node {} · inherit {}", report.index, report.node, report.inherit.id()));
    let assessment = &report.assessment;
    let badges: Vec<Badge> = Badge::of(&assessment.findings).collect();
    let text = if badges.is_empty() {
        "findings: none".to_owned()
    } else {
        format!("findings: {}", badges.iter().map(|b| b.label()).collect::<Vec<_>>().join(", "))
    };
    let color = badges.first().map_or(ui.visuals().text_color(), |b| b.color());
    let explanation = badges.iter().map(|b| b.explanation()).collect::<Vec<_>>().join("; ");
    ui.label(RichText::new(text).color(color).strong()).on_hover_text(explanation);
    let (shear, stretch) = (compact(assessment.shear_deg), compact(assessment.stretch_deg));
    ui.label(format!("shear {shear}°   stretch angle {stretch}°"));
    ui.horizontal_wrapped(|ui| {
        copy_button(ui, shared, &reports);
        why::header(ui, shared, why, bone);
    });
    egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
        why::ui(ui, shared, why, bone);
        morph_weights(ui, shared, bone);
        let local = shared.frame.pose.local[bone].matrix();
        let tolerance = shared.settings.tolerances.min_anisotropy;
        let authored = assessment.parts.authored(shared.doc.rig.skeleton.length_scales()[bone]);
        section(ui, "Model", &shared.frame.pose.model.model[bone], &authored, tolerance);
        section(ui, "Local", &local, &crate::math::decompose(&local), tolerance);
    });
}

/// Copies what `inspect --format json` prints; for a moment after, the button says it did (in its own width, so
/// nothing beside or below it moves).
fn copy_button(ui: &mut Ui, shared: &Shared, reports: &[BoneReport]) {
    let copied_at = ui.scope_id().with("copied-at");
    let now = ui.input(|i| i.time);
    let copied = ui.data(|d| d.get_temp::<f64>(copied_at)).is_some_and(|t| now - t < COPIED_SECONDS);
    let button = super::text::steady_button(ui, if copied { "Copied" } else { "Copy as JSON" }, "Copy as JSON");
    let hint = "every bone now, as `bonescope inspect FILE --time T --format json` prints it";
    if ui.add(button).on_hover_text(hint).clicked()
        && let Ok(json) = serde_json::to_string_pretty(&inspect_report(shared, reports.to_vec()))
    {
        ui.ctx().copy_text(json);
        ui.data_mut(|d| d.insert_temp(copied_at, now));
    }
    if copied {
        ui.ctx().request_repaint_after(std::time::Duration::from_millis(250));
    }
}

/// How long the Copy button says "Copied".
const COPIED_SECONDS: f64 = 2.0;

/// What `inspect --format json` prints for the document at the current time: every bone, the layers, the bind check.
fn inspect_report(shared: &Shared, bones: Vec<BoneReport>) -> LayeredInspectReport {
    let doc = &*shared.doc;
    let inherit = doc.setup().modes.label().to_owned();
    let file = doc.path.as_ref().map_or_else(|| "demo".to_owned(), |p| p.display().to_string());
    let samples = vec![SampleReport { time: *shared.time, bones }];
    LayeredInspectReport::new(file, &doc.evaluation(), inherit, samples)
}

/// The morph-target weights in effect on the meshes the bone carries (animated by the clip, or the meshes' own).
fn morph_weights(ui: &mut Ui, shared: &Shared, bone: usize) {
    let morph = &shared.frame.pose.morph;
    for mesh in shared.doc.rig.meshes.iter().filter(|m| m.bone == bone && !m.morph_targets.is_empty()) {
        ui.separator();
        ui.label(RichText::new(format!("Morph weights · {}", mesh.name)).strong());
        let weights = morph.weights(mesh);
        Grid::new(("morph", &mesh.name)).striped(true).show(ui, |ui| {
            for (target, weight) in mesh.morph_targets.iter().zip(weights.iter()) {
                ui.label(&target.name);
                ui.label(RichText::new(format!("{weight:>7.3}")).monospace());
                ui.add(egui::ProgressBar::new(weight.clamp(0.0, 1.0) as f32).desired_width(80.0));
                ui.end_row();
            }
        });
    }
}

/// A matrix and its parts, in columns that fit a narrow panel (numbers in at most 7 characters, see
/// [`compact`]). Where the scale factors are equal within `anisotropy` the stretch rotation `U` is undetermined (any
/// frame diagonalises a uniform scale), so it is shown as the identity it is equivalent to.
fn section(ui: &mut Ui, title: &str, matrix: &DMat4, parts: &AffineParts, anisotropy: f64) {
    ui.separator();
    ui.label(RichText::new(title).strong());
    Grid::new(format!("{title}-matrix")).spacing([COLUMN_GAP, 2.0]).striped(true).show(ui, |ui| {
        for row in 0..4 {
            numbers(ui, &(0..4).map(|col| matrix.col(col)[row]).collect::<Vec<_>>());
            ui.end_row();
        }
    });
    let uniform = parts.anisotropy() <= anisotropy;
    let stretch = if uniform { glam::DQuat::IDENTITY } else { parts.stretch };
    Grid::new(format!("{title}-parts")).spacing([COLUMN_GAP, 2.0]).show(ui, |ui| {
        let rows: [(&str, &str, Vec<f64>); 6] = [
            ("translation", "T: x y z", parts.translation.to_array().to_vec()),
            ("rotation", "R as a quaternion: x y z w", parts.rotation.to_array().to_vec()),
            ("stretch U", "U as a quaternion: x y z w", stretch.to_array().to_vec()),
            ("stretch °", "U's angle in degrees", vec![parts.stretch_angle_deg_within(anisotropy)]),
            ("scale k", "K: the scale along U's axes", parts.scale.to_array().to_vec()),
            ("sign f", "F: -1 mirrors", vec![parts.sign]),
        ];
        for (name, hint, values) in rows {
            ui.label(name).on_hover_text(hint);
            numbers(ui, &values);
            ui.end_row();
        }
    });
}

/// Points between the inspector's number columns.
const COLUMN_GAP: f32 = 6.0;

/// One grid cell per value, right-aligned in a fixed width (so columns line up and nothing shifts as values
/// change), the exact value on hover.
fn numbers(ui: &mut Ui, values: &[f64]) {
    for &value in values {
        let text = RichText::new(format!("{:>7}", compact(value))).monospace();
        ui.label(text).on_hover_text(precise(value));
    }
}
