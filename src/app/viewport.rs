//! The viewport panel: view toggles and the camera controls around the shared painting code of `view`.
//!
//! Left drag orbits (a 2D view turns into the 3D one), right or middle drag pans, the wheel zooms, a click
//! selects the bone under the pointer, F frames the selection (or everything).

use egui::{Sense, Ui};
use glam::DVec2;

use super::document::{Document, Ghost};
use super::pane::{Pane, Place, Visibility};
use super::panel::{Panel, Shared};
use crate::model::Choice;
use crate::view::{Bounds, Camera, DrawnPose, Palette, Scene, Triads, ViewKind, ground, motion, paint};

/// Poses sampled to find the bounds of a clip's motion.
const MOTION_SAMPLES: usize = 24;

/// Whether the canvas paints its background.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CanvasFill {
    Painted,
    /// Left out: headless renders put it behind the picture after reading it back, because a window-sized fill
    /// costs the software rasteriser as much as everything else it draws together.
    Left,
}

#[derive(Default)]
pub struct Viewport {
    /// Points to frame once the canvas knows its shape (framing fits them to the aspect ratio).
    framing: Option<Vec<glam::DVec3>>,
    /// The figure the camera follows over the ground, where the clip travels.
    follow: Option<Follow>,
    /// Where messages stack, at the lower left of it (see [`Viewport::messages_rect`]).
    messages: Option<egui::Rect>,
}

impl Viewport {
    /// Where messages stack, in their lower left corner and as wide: the legend's column, which the figure is
    /// framed beside, so that a message on opening covers none of it; without the legend the canvas's left, clear
    /// of the caption at its right.
    pub fn messages_rect(&self) -> Option<egui::Rect> {
        self.messages
    }

    /// Frames the figure in every posture of the current clip (through its layers), at the canvas's next frame;
    /// where the clip travels, the camera follows the figure from then on (see [`motion`]).
    pub fn frame_all(&mut self, doc: &Document) {
        let evaluation = doc.evaluation();
        let pose_at = |time| evaluation.pose_at(time).model.model;
        let motion = motion(&doc.rig, doc.clip(), doc.span(), MOTION_SAMPLES, pose_at);
        self.framing = Some(motion.points);
        // The points stand their anchor above the origin: the first frame moves the camera to where it is.
        self.follow = motion.anchor.map(|bone| Follow { bone, at: glam::DVec3::ZERO });
    }

    /// Applies a pending [`Viewport::frame_all`] now, for a canvas of this aspect ratio.
    pub fn frame_now(&mut self, camera: &mut Camera, aspect: f64) {
        if let Some(points) = self.framing.take() {
            camera.frame_points(&points, aspect);
        }
    }

    /// The picture alone, filling the space left: what headless renders of the viewport show.
    pub fn canvas(&mut self, ui: &mut Ui, shared: &mut Shared, background: CanvasFill) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "viewport"));
        let rig = shared.doc.rig.clone();
        let mut scene = Scene::new(&rig, shared.frame.primary.clone(), shared.settings.scene);
        scene.ghost = shared.frame.ghost.clone();
        scene.ghost_label = match (&shared.doc.ghost, &shared.doc.compared) {
            (Some(Ghost::Compared), Some(compared)) => format!("ghost: {}", compared.title()),
            (ghost, _) => ghost.as_ref().map_or_else(String::new, |g| format!("ghost: {}", g.label())),
        };
        scene.caption = caption(shared);
        scene.selected = shared.selection.clone();
        scene.neutral_shear_deg = shared.settings.tolerances.min_shear_deg;
        if shared.settings.scene.bind_pose {
            scene.bind_pose = Some(DrawnPose::bind(&rig, &scene.primary));
        }
        let picture = paint::picture_rect(rect, &scene);
        self.messages = Some(
            paint::legend_rect(rect, &scene)
                .unwrap_or_else(|| rect.with_max_x(rect.max.x - rect.width() * super::notifications::CAPTION_SIDE)),
        );
        self.frame_now(&mut shared.settings.camera, aspect(picture));
        if let Some(follow) = &mut self.follow {
            follow.step(&scene.primary, &mut shared.settings.camera);
        }
        navigate(ui, &response, picture, &mut shared.settings.camera);
        if response.clicked()
            && let Some(at) = response.interact_pointer_pos()
        {
            let extend = ui.input(|i| i.modifiers.command || i.modifiers.shift);
            match paint::pick(&scene, &shared.settings.camera, rect, at) {
                Some(bone) => shared.select(bone, extend),
                None if !extend => shared.selection.clear(),
                None => {}
            }
        }
        if response.hovered() && ui.input(|i| i.key_pressed(egui::Key::F)) {
            frame_selection(&scene, shared.selection, &mut shared.settings.camera, aspect(picture));
        }
        let camera = &shared.settings.camera;
        let mut palette = Palette::new(ui.visuals().dark_mode);
        if background == CanvasFill::Left {
            palette.background = egui::Color32::TRANSPARENT;
        }
        paint::paint(ui.painter(), rect, camera, &scene, &palette);
    }
}

/// A camera that keeps a travelling figure where it was framed: it moves over the ground as its anchor bone does
/// (a pan or an orbit stays as the user left it, relative to the figure).
struct Follow {
    bone: usize,
    /// Where over the ground the anchor was when the camera last moved with it.
    at: glam::DVec3,
}

impl Follow {
    fn step(&mut self, pose: &DrawnPose, camera: &mut Camera) {
        let Some(head) = pose.model.get(self.bone).map(|m| ground(m.w_axis.truncate())) else { return };
        camera.target += head - self.at;
        self.at = head;
    }
}

/// File and clip, time, the modes the pose is evaluated with, and its layers.
fn caption(shared: &Shared) -> Vec<String> {
    let doc = &*shared.doc;
    let clip = doc.clip().map_or_else(|| "rest pose".to_owned(), |c| c.label());
    let modes = doc.common_mode().map_or_else(|| "mixed modes".to_owned(), |m| format!("mode: {}", m.id()));
    let mut lines = vec![format!("{} · {clip}", doc.title()), shared.time_text(*shared.time), modes];
    let layers = doc.layers().summary(&doc.rig, doc.clip());
    lines.extend(layers.split("; ").filter(|l| !l.is_empty()).map(str::to_owned));
    lines
}

/// Orbit, pan and zoom from the pointer.
fn navigate(ui: &Ui, response: &egui::Response, rect: egui::Rect, camera: &mut Camera) {
    if response.dragged_by(egui::PointerButton::Primary) {
        let d = response.drag_delta();
        camera.orbit(DVec2::new(f64::from(d.x), f64::from(d.y)) * 0.008);
    }
    if response.dragged_by(egui::PointerButton::Secondary) || response.dragged_by(egui::PointerButton::Middle) {
        let d = response.drag_delta() / rect.height().max(1.0);
        camera.pan(DVec2::new(f64::from(d.x), f64::from(d.y)));
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            // Towards the pointer, about 14 % per wheel notch (a notch scrolls 50 points).
            let at = response.hover_pos().map_or(DVec2::ZERO, |p| {
                let d = (p - rect.center()) / rect.height().max(1.0);
                DVec2::new(f64::from(d.x), f64::from(d.y))
            });
            camera.zoom_at((f64::from(scroll) * 0.0026).exp(), at);
        }
    }
}

/// Frames the selected bones and everything drawn below them (every descendant's joint, and the tails of the last ones:
/// `F` on the hips shows the whole figure), at least a few gizmo sizes across so a single joint does not fill the
/// picture; everything when nothing is selected.
fn frame_selection(scene: &Scene, selection: &[usize], camera: &mut Camera, aspect: f64) {
    let below: Vec<usize> = below(&scene.rig.skeleton, selection).into_iter().filter(|&b| scene.shows(b)).collect();
    let heads = below.iter().map(|&b| scene.primary.head(b));
    let tails = below.iter().filter_map(|&b| scene.tail(&scene.primary, b));
    let selected = Bounds::of(heads.chain(tails)).map(|b| {
        let half = glam::DVec3::splat(scene.gizmo_size * 2.0);
        Bounds { min: b.min.min(b.center() - half), max: b.max.max(b.center() + half) }
    });
    if let Some(bounds) = selected.or_else(|| scene.bounds()) {
        camera.frame(&bounds, aspect);
    }
}

/// The bones of `selection` and all their descendants (parents come before children, so one pass finds them).
fn below(skeleton: &crate::model::Skeleton, selection: &[usize]) -> Vec<usize> {
    let mut inside = vec![false; skeleton.len()];
    for &bone in selection.iter().filter(|&&b| b < skeleton.len()) {
        inside[bone] = true;
    }
    for bone in 0..skeleton.len() {
        inside[bone] |= skeleton.parent(bone).is_some_and(|p| inside[p]);
    }
    (0..skeleton.len()).filter(|&b| inside[b]).collect()
}

fn aspect(rect: egui::Rect) -> f64 {
    f64::from(rect.width().max(1.0)) / f64::from(rect.height().max(1.0))
}

/// The view and display toggles: a narrow viewport wraps them onto a second row rather than hide the last ones
/// past its edge (the row's height changes only when the viewport's width does, never as the user works).
fn toolbar(ui: &mut Ui, shared: &mut Shared) {
    ui.horizontal_wrapped(|ui| toggles(ui, shared));
}

fn toggles(ui: &mut Ui, shared: &mut Shared) {
    for view in ViewKind::ALL {
        ui.selectable_value(&mut shared.settings.camera.view, view, view.label());
    }
    ui.separator();
    let has_mesh = !shared.doc.rig.meshes.is_empty();
    let o = &mut shared.settings.scene;
    ui.toggle_value(&mut o.bones, "Bones");
    triads_picker(ui, &mut o.triads);
    ui.toggle_value(&mut o.boxes, "Boxes").on_hover_text("a unit box per bone: shear slants it");
    ui.toggle_value(&mut o.mesh, "Mesh");
    // Greyed, not gone, where there is no mesh to paint: the toggles after it stay where they are.
    ui.add_enabled_ui(has_mesh && o.mesh, |ui| {
        ui.toggle_value(&mut o.shear, "Shear")
            .on_hover_text("the mesh painted by the shear each vertex is skinned with (legend in degrees)")
    })
    .response
    .on_disabled_hover_text("paints the mesh: no mesh shown");
    ui.toggle_value(&mut o.wireframe, "Wireframe");
    ui.toggle_value(&mut o.bind_pose, "Bind pose");
    ui.toggle_value(&mut o.helpers, "Helpers")
        .on_hover_text("cameras, lights, meshes' nodes and other helpers as bones");
    ui.toggle_value(&mut o.names, "Names");
    ui.toggle_value(&mut o.grid, "Grid");
    ui.toggle_value(&mut o.legend, "Legend");
}

/// Whose axis triads are drawn.
fn triads_picker(ui: &mut Ui, triads: &mut Triads) {
    let label = ui.label("Axes");
    egui::ComboBox::from_id_salt("triads")
        .selected_text(triads.id())
        .show_ui(ui, |ui| {
            for &choice in Triads::ALL {
                ui.selectable_value(triads, choice, choice.id()).on_hover_text(choice.description());
            }
        })
        .response
        .labelled_by(label.id)
        .on_hover_text("whose axis triads are drawn, at the rig's size: a sheared frame loses its right angles");
}

impl Panel for Viewport {
    fn pane(&self) -> Pane {
        Pane::VIEWPORT
    }

    fn place(&self) -> Place {
        Place::Centre(0.64)
    }

    fn visibility(&self) -> Visibility {
        Visibility::Always
    }

    /// The view toggles above the canvas.
    fn ui(&mut self, ui: &mut Ui, shared: &mut Shared) {
        toolbar(ui, shared);
        self.canvas(ui, shared, CanvasFill::Painted);
    }
}
