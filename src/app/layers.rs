//! The Layers panel: the runtime techniques layered on the clip (bind weight, interpolation, blend, additive,
//! crossfade, shake, uniform scale, targets), the bind pose check and the stretch-quaternion storage report; first,
//! the file's meshes that are not drawn, and why.
//!
//! A technique's section starts open when its layer is on. Edits go to a copy of the document's layers; the
//! document takes the copy at the end of the frame (it checks every clip and bone index, so a bad combination is
//! reported, not applied).

use egui::{CollapsingHeader, DragValue, RichText, Slider, Ui};
use glam::{DQuat, DVec3};

use super::document::Ghost;
use super::pane::{Pane, Place, Visibility};
use super::panel::{Panel, Shared};
use crate::analysis::BindCheck;
use crate::analysis::storage::StorageReport;
use crate::eval::Layers;
use crate::eval::layers::{Additive, Blend, Crossfade, Shake, ShakeParams, SyncedCycle, Target};
use crate::model::{Choice, Rig, Skeleton, Transform};
use crate::view::Badge;

/// The panel's own state (the bind check and the storage report are the work's, computed off the UI thread: each
/// walks the whole clip).
#[derive(Default)]
pub struct LayersPanel {
    /// How many bones the uniform-scale layer had in the last frame: a bone added elsewhere (the Inspector's Why?
    /// section) opens its section, where it is undone.
    uniform_bones: usize,
}

impl Panel for LayersPanel {
    fn pane(&self) -> Pane {
        Pane::LAYERS
    }

    fn place(&self) -> Place {
        Place::Right(0.45)
    }

    fn visibility(&self) -> Visibility {
        Visibility::Hidden
    }

    fn ui(&mut self, ui: &mut Ui, shared: &mut Shared) {
        let mut layers = shared.doc.layers().clone();
        egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
            not_drawn_section(ui, &shared.doc.rig);
            bind_section(ui, shared, &mut layers);
            interpolation_section(ui, shared, &mut layers);
            blend_section(ui, shared, &mut layers);
            additive_section(ui, shared, &mut layers);
            crossfade_section(ui, shared, &mut layers);
            shake_section(ui, shared, &mut layers);
            uniform_section(ui, shared, &mut layers, std::mem::take(&mut self.uniform_bones));
            targets_section(ui, shared, &mut layers);
            storage_section(ui, shared);
        });
        if layers != *shared.doc.layers()
            && let Err(error) = shared.doc.set_layers(&layers)
        {
            ui.colored_label(Badge::Stretched.color(), error.to_string());
        }
        self.uniform_bones = shared.doc.layers().uniform_scale.len();
    }
}

/// The bind weight, and the bind check: joints whose bind matrices break the skin (a warning), and joints the stored
/// pose holds away from their bind (a note).
fn bind_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    CollapsingHeader::new("Bind pose").default_open(true).show(ui, |ui| {
        weight_slider(ui, &mut layers.bind_weight, "clip weight").on_hover_text("0: the bind pose, 1: the clip");
        ui.checkbox(&mut shared.settings.scene.bind_pose, "Show the bind pose");
        if shared.doc.rig.skins.is_empty() {
            ui.label(RichText::new("no skinned mesh in the file: the bind pose is the rest pose").weak());
            return;
        }
        match shared.work.bind_check(shared.doc) {
            Some(check) => bind_report(ui, check),
            None => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label("checking the bind matrices…");
                });
            }
        }
    });
}

/// The stretch-quaternion storage of the current clip (`docs/decomposition.md`), measured when asked, off the UI
/// thread.
fn storage_section(ui: &mut Ui, shared: &mut Shared) {
    CollapsingHeader::new("Stretch-quaternion storage").show(ui, |ui| {
        if ui.button("Measure the clip").clicked() {
            shared.work.measure_storage(shared.doc);
        }
        match shared.work.storage(shared.doc) {
            (Some(report), _) => storage_table(ui, report),
            (None, true) => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label("measuring the clip…");
                });
            }
            (None, false) => {
                ui.label(RichText::new("Marks the bones stretched in any frame and prices their channel.").weak());
            }
        }
    });
}

fn bind_report(ui: &mut Ui, check: &BindCheck) {
    if check.broken.is_empty() && check.posed.is_empty() {
        ui.label("inverse bind matrices agree with the rest pose");
    }
    if !check.broken.is_empty() {
        let count = check.broken.len();
        let joints = if count == 1 { "joint's bind matrix disagrees" } else { "joints' bind matrices disagree" };
        let text = format!("{count} {joints} with the joints around: the skin is broken there");
        ui.colored_label(Badge::Stretched.color(), text);
        egui::Grid::new("bind-mismatches").striped(true).show(ui, |ui| {
            ui.label("joint");
            ui.label("distance");
            ui.label("angle°");
            ui.end_row();
            for m in check.broken.iter().take(12) {
                ui.label(&m.name);
                if m.last_row.is_some() {
                    ui.label("not rigid").on_hover_text(m.says());
                } else {
                    ui.monospace(format!("{:.4}", m.gap.distance));
                    ui.monospace(format!("{:.3}", m.gap.angle_deg));
                }
                ui.end_row();
            }
        });
    }
    if let Some(note) = check.note() {
        ui.label(RichText::new(format!("note: {note}")).weak());
    }
}

fn interpolation_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    CollapsingHeader::new("Interpolation").default_open(!layers.interpolation.is_authored()).show(ui, |ui| {
        value_combo(ui, "keys", &mut layers.interpolation.keys);
        value_combo(ui, "rotations", &mut layers.interpolation.rotation);
        let compare = shared.doc.ghost == Some(Ghost::Unlayered);
        if !layers.interpolation.is_authored() && !compare && ui.button("Show the authored clip as the ghost").clicked()
        {
            shared.doc.ghost = Some(Ghost::Unlayered);
        }
    });
}

fn blend_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    let rig = shared.doc.rig.clone();
    let main = shared.doc.setup().clip;
    CollapsingHeader::new("Blend").default_open(layers.blend.is_some()).show(ui, |ui| {
        let default = || Blend { clip: other_clip(&rig, main), weight: 0.5, sync: true, rotation: Default::default() };
        enable(ui, "blend a second clip", &mut layers.blend, default);
        let Some(blend) = &mut layers.blend else { return };
        clip_combo(ui, "with", &rig, &mut blend.clip);
        weight_slider(ui, &mut blend.weight, "a").on_hover_text("0: the main clip, 1: the blended one");
        ui.checkbox(&mut blend.sync, "sync (normalised time)");
        value_combo(ui, "rotations", &mut blend.rotation);
        if blend.sync {
            let t1 = shared.doc.clip().map_or(0.0, |c| c.span().length());
            let t2 = rig.clips.get(blend.clip).map_or(0.0, |c| c.span().length());
            let cycle = SyncedCycle::new(t1, t2, blend.weight);
            ui.monospace(format!("cycle (T2 − T1)·a + T1 = {:.4} s", cycle.length));
            ui.monospace(format!("rates T1/len {:.4}, T2/len {:.4}", cycle.rates[0], cycle.rates[1]));
        }
    });
}

fn additive_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    let rig = shared.doc.rig.clone();
    let main = shared.doc.setup().clip;
    CollapsingHeader::new("Additive").default_open(layers.additive.is_some()).show(ui, |ui| {
        let default = || Additive {
            clip: other_clip(&rig, main),
            reference: Default::default(),
            order: Default::default(),
            weight: 1.0,
        };
        enable(ui, "add a clip's difference", &mut layers.additive, default);
        let Some(additive) = &mut layers.additive else { return };
        clip_combo(ui, "clip", &rig, &mut additive.clip);
        value_combo(ui, "difference from", &mut additive.reference);
        value_combo(ui, "order", &mut additive.order)
            .on_hover_text("local: q_base · q_add (in the bone's frame); global: q_add · q_base (in the parent's)");
        weight_slider(ui, &mut additive.weight, "weight");
    });
}

fn crossfade_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    let rig = shared.doc.rig.clone();
    let main = shared.doc.setup().clip;
    // The fade's times count from the main clip's start: by default it begins 0.25 s before the clip's end.
    let length = shared.doc.clip().map_or(0.0, |c| c.span().length());
    CollapsingHeader::new("Crossfade").default_open(layers.crossfade.is_some()).show(ui, |ui| {
        let default = || Crossfade {
            clip: other_clip(&rig, main),
            at: (length - 0.25).max(0.0),
            duration: 0.25_f64.min(length.max(0.01)),
            curve: Default::default(),
        };
        enable(ui, "fade into another clip", &mut layers.crossfade, default);
        let Some(fade) = &mut layers.crossfade else { return };
        clip_combo(ui, "into", &rig, &mut fade.clip);
        seconds(ui, "starts at", "seconds after the main clip's start", &mut fade.at);
        seconds(ui, "lasts", "seconds from the main clip alone to the other alone", &mut fade.duration);
        value_combo(ui, "weights", &mut fade.curve);
    });
}

fn shake_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    let inspected = shared.inspected();
    let skeleton = &shared.doc.rig.skeleton;
    CollapsingHeader::new("Procedural shake").default_open(layers.shake.is_some()).show(ui, |ui| {
        let default = || Shake { bone: inspected.unwrap_or(0), params: ShakeParams::default() };
        enable(ui, "shake a bone and the bones below", &mut layers.shake, default);
        let Some(shake) = &mut layers.shake else { return };
        ui.horizontal(|ui| {
            ui.label(format!("bone: {}", skeleton.bone(shake.bone).name));
            if let Some(bone) = inspected.filter(|&b| b != shake.bone)
                && ui.button("use the selected bone").clicked()
            {
                shake.bone = bone;
            }
        });
        let p = &mut shake.params;
        egui::Grid::new("shake-params").show(ui, |ui| {
            labelled(ui, "speed (rad/s)", DragValue::new(&mut p.speed).speed(0.5));
            labelled(ui, "amplitude", DragValue::new(&mut p.amplitude).speed(0.01));
            labelled(ui, "attenuation", DragValue::new(&mut p.attenuation).speed(0.01));
            labelled(ui, "fade (1: off)", DragValue::new(&mut p.fade).speed(0.01).range(0.0..=1.0));
        });
        vector(ui, "translation", &mut p.translation);
        vector(ui, "rotation (rad)", &mut p.rotation);
    });
}

/// The bones whose local scale is replaced by its uniform part (the volume kept, `∛|k₁·k₂·k₃|` on every axis): a
/// squash that shears the bones below no longer does. Opens when a bone was added since the last frame (`before`
/// bones then), so that the Why? section's fix is seen here and undone with its remove button.
fn uniform_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers, before: usize) {
    let skeleton = &shared.doc.rig.skeleton;
    let added = layers.uniform_scale.len() > before;
    let header = CollapsingHeader::new("Uniform scale").default_open(!layers.uniform_scale.is_empty());
    header.open(added.then_some(true)).show(ui, |ui| {
        if let Some(bone) = shared.inspected().filter(|b| !layers.uniform_scale.contains(b))
            && ui.button(format!("Make {}'s scale uniform", skeleton.bone(bone).name)).clicked()
        {
            layers.make_scale_uniform(bone);
        }
        removable_rows(ui, &mut layers.uniform_scale, |ui, bone| {
            ui.label(&skeleton.bone(*bone).name);
        });
        if layers.uniform_scale.is_empty() {
            ui.label(
                RichText::new("Select a bone and make its scale uniform: its squash then shears no bone below it.")
                    .weak(),
            );
        }
    });
}

/// One row per item, drawn by `row`, each with a "remove" button that takes it out of `items`.
fn removable_rows<T>(ui: &mut Ui, items: &mut Vec<T>, mut row: impl FnMut(&mut Ui, &mut T)) {
    let mut removed = None;
    for (i, item) in items.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            row(ui, item);
            if ui.small_button("remove").clicked() {
                removed = Some(i);
            }
        });
    }
    if let Some(i) = removed {
        items.remove(i);
    }
}

fn targets_section(ui: &mut Ui, shared: &mut Shared, layers: &mut Layers) {
    let skeleton = &shared.doc.rig.skeleton;
    CollapsingHeader::new("World-space targets").default_open(!layers.targets.is_empty()).show(ui, |ui| {
        if let Some(bone) = shared.inspected()
            && ui.button(format!("Pin {} where it is now", skeleton.bone(bone).name)).clicked()
        {
            let rotation = chain_rotation(skeleton, &shared.frame.pose.local, bone);
            layers.targets.retain(|t| t.bone != bone);
            layers.targets.push(Target { bone, rotation, weight: 1.0 });
        }
        removable_rows(ui, &mut layers.targets, |ui, target| {
            ui.label(&skeleton.bone(target.bone).name);
            weight_slider(ui, &mut target.weight, "weight");
        });
        if layers.targets.is_empty() {
            ui.label(
                RichText::new("Select a bone and pin it: its model rotation then holds while the rest moves.").weak(),
            );
        }
    });
}

/// The model rotation of `bone` as the targets read it: its chain of local rotations from the root.
fn chain_rotation(skeleton: &Skeleton, local: &[Transform], bone: usize) -> DQuat {
    let mut rotation = local[bone].rotation;
    let mut at = skeleton.parent(bone);
    while let Some(parent) = at {
        rotation = local[parent].rotation * rotation;
        at = skeleton.parent(parent);
    }
    rotation.normalize()
}

fn storage_table(ui: &mut Ui, report: &StorageReport) {
    let marked: Vec<&str> = report.marked.iter().map(|m| m.name.as_str()).collect();
    ui.label(format!("{} frames × {} bones; marked: {}", report.frames, report.bones, marked.len()));
    if !marked.is_empty() {
        ui.label(RichText::new(marked.join(", ")).color(Badge::Stretched.color()));
    }
    egui::Grid::new("storage").striped(true).show(ui, |ui| {
        ui.label("");
        ui.label("bytes");
        ui.label("max error");
        ui.label("mean error");
        ui.end_row();
        let rows = [
            ("TRS + stretch", report.bytes_with_stretch, report.reconstruction),
            ("TRS only", report.bytes_trs, report.trs_only),
        ];
        for (name, bytes, error) in rows {
            ui.label(name);
            ui.monospace(bytes.to_string());
            ui.monospace(format!("{:.2e}", error.bone_axes.max));
            ui.monospace(format!("{:.2e}", error.bone_axes.mean));
            ui.end_row();
        }
    });
    ui.label(
        RichText::new(format!("errors at points {} along each bone's axes, model units", report.probe_distance)).weak(),
    );
}

/// A checkbox that turns an optional layer on (with `default`) and off.
fn enable<T>(ui: &mut Ui, label: &str, layer: &mut Option<T>, default: impl FnOnce() -> T) {
    let mut on = layer.is_some();
    if ui.checkbox(&mut on, label).changed() {
        *layer = on.then(default);
    }
}

/// Another clip than the main one when there is one, for a layer just switched on.
fn other_clip(rig: &Rig, main: Option<usize>) -> usize {
    (0..rig.clips.len()).find(|&c| Some(c) != main).or(main).unwrap_or(0)
}

fn clip_combo(ui: &mut Ui, label: &str, rig: &Rig, clip: &mut usize) {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        let current = rig.clips.get(*clip).map_or_else(|| format!("animation {clip}"), |c| c.label());
        egui::ComboBox::from_id_salt(("layer-clip", label.id))
            .selected_text(current)
            .show_ui(ui, |ui| {
                for c in &rig.clips {
                    ui.selectable_value(clip, c.index, super::text::clip_choice(c));
                }
            })
            .response
            .labelled_by(label.id);
    });
}

/// A combo box over the values of one of the library's options, named as the command line names them and described
/// on hover.
fn value_combo<T: Choice>(ui: &mut Ui, label: &str, value: &mut T) -> egui::Response {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        egui::ComboBox::from_id_salt(("layer-option", label.id))
            .selected_text(value.id())
            .show_ui(ui, |ui| {
                for &v in T::ALL {
                    ui.selectable_value(value, v, v.id()).on_hover_text(v.description());
                }
            })
            .response
            .labelled_by(label.id)
    })
    .inner
}

fn weight_slider(ui: &mut Ui, weight: &mut f64, label: &str) -> egui::Response {
    ui.add(Slider::new(weight, 0.0..=1.0).text(label))
}

fn seconds(ui: &mut Ui, label: &str, hint: &str, value: &mut f64) {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        let field = DragValue::new(value).speed(0.01).range(0.0..=f64::MAX).suffix(" s");
        ui.add(field).labelled_by(label.id).on_hover_text(hint);
    });
}

fn labelled(ui: &mut Ui, label: &str, widget: DragValue) {
    let label = ui.label(label);
    ui.add(widget).labelled_by(label.id);
    ui.end_row();
}

fn vector(ui: &mut Ui, label: &str, v: &mut DVec3) {
    ui.horizontal(|ui| {
        let label = ui.label(label);
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            ui.add(DragValue::new(c).speed(0.01)).labelled_by(label.id);
        }
    });
}

/// The file's meshes that are not drawn, and why, as `inspect` notes them: a figure of bones alone says what it
/// lacks. Nothing on a file whose every mesh is drawn.
fn not_drawn_section(ui: &mut Ui, rig: &Rig) {
    let notes: Vec<&str> = rig.meshes_not_drawn().collect();
    if notes.is_empty() {
        return;
    }
    let title = RichText::new("Meshes not drawn").color(Badge::NonUniform.color());
    CollapsingHeader::new(title).default_open(true).show(ui, |ui| {
        for note in notes {
            ui.add(egui::Label::new(note).wrap());
        }
    });
}
