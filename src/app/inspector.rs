//! The selected bone at the current time: local and model matrices, every decomposed part, the findings, the
//! morph-target weights of the meshes it carries, and a button that copies the same JSON `bonescope inspect` prints.

use egui::{Grid, RichText, Ui};
use glam::DMat4;

use super::Shared;
use super::{ModeChoice, ModeScope};
use crate::analysis::report::{BoneReport, LayeredInspectReport, SampleReport};
use crate::math::AffineParts;
use crate::view::Badge;

pub fn ui(ui: &mut Ui, shared: &mut Shared) {
    ui.heading("Inspector");
    let Some(bone) = shared.inspected() else {
        ui.label(RichText::new("Select a bone in the viewport or the list.").weak());
        return;
    };
    let reports =
        BoneReport::all(&shared.doc.rig.skeleton, &shared.doc.modes, &shared.frame.pose, &shared.settings.tolerances);
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
    ui.label(format!("shear {:.4}°   stretch angle {:.4}°", assessment.shear_deg, assessment.stretch_deg));
    ui.horizontal(|ui| {
        let copied_at = ui.scope_id().with("copied-at");
        let now = ui.input(|i| i.time);
        let hint = "every bone now, as `bonescope inspect FILE --time T --format json` prints it";
        if ui.button("Copy as JSON").on_hover_text(hint).clicked()
            && let Ok(json) = serde_json::to_string_pretty(&inspect_report(shared, reports.clone()))
        {
            ui.ctx().copy_text(json);
            ui.data_mut(|d| d.insert_temp(copied_at, now));
        }
        if ui.data(|d| d.get_temp::<f64>(copied_at)).is_some_and(|t| now - t < 3.0) {
            ui.label(RichText::new("copied to the clipboard").weak());
            ui.ctx().request_repaint_after(std::time::Duration::from_millis(500));
        }
    });
    egui::ScrollArea::both().auto_shrink([false, false]).show(ui, |ui| {
        morph_weights(ui, shared, bone);
        let local = shared.frame.pose.local[bone].matrix();
        let tolerance = shared.settings.tolerances.min_anisotropy;
        section(ui, "Model", &shared.frame.pose.model.model[bone], &assessment.parts, tolerance);
        section(ui, "Local", &local, &crate::math::decompose(&local), tolerance);
    });
}

/// What `inspect --format json` prints for the document at the current time: every bone, the layers, the bind check.
fn inspect_report(shared: &Shared, bones: Vec<BoneReport>) -> LayeredInspectReport {
    let doc = &*shared.doc;
    let inherit = doc.current_choice(0, ModeScope::All).map_or("mixed", ModeChoice::label).to_owned();
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

/// A matrix and its parts. Where the scale factors are equal within `anisotropy` the stretch rotation `U` is
/// undetermined (any frame diagonalises a uniform scale), so it is shown as the identity it is equivalent to.
fn section(ui: &mut Ui, title: &str, matrix: &DMat4, parts: &AffineParts, anisotropy: f64) {
    ui.separator();
    ui.label(RichText::new(title).strong());
    Grid::new(format!("{title}-matrix")).striped(true).show(ui, |ui| {
        for row in 0..4 {
            for col in 0..4 {
                ui.label(RichText::new(format!("{:>9.4}", matrix.col(col)[row])).monospace());
            }
            ui.end_row();
        }
    });
    Grid::new(format!("{title}-parts")).show(ui, |ui| {
        // Fixed-width numbers, so columns line up and nothing shifts as values change.
        let v = |values: &[f64]| values.iter().map(|x| format!("{:>8.4}", x + 0.0)).collect::<Vec<_>>().join(" ");
        let uniform = parts.anisotropy() <= anisotropy;
        let stretch = if uniform { glam::DQuat::IDENTITY } else { parts.stretch };
        let rows = [
            ("translation", v(&parts.translation.to_array())),
            ("rotation q", v(&parts.rotation.to_array())),
            ("stretch U", format!("{}  ({:.3}°)", v(&stretch.to_array()), parts.stretch_angle_deg_within(anisotropy))),
            ("scale k", v(&parts.scale.to_array())),
            ("sign f", format!("{:>8}", parts.sign)),
        ];
        for (name, value) in rows {
            ui.label(name);
            ui.label(RichText::new(value).monospace());
            ui.end_row();
        }
    });
}
