//! Painting a [`Scene`] with egui's painter: the one drawing path of the app's viewport and of headless renders.
//!
//! Solid geometry (the translucent skinned mesh, then bones as octahedra over it) is flat-shaded and drawn back to
//! front (painter's algorithm); lines and markers (grid, axis triads, boxes, joints, names) go on top so they are
//! never hidden.

use egui::epaint::Mesh as EguiMesh;
use egui::{Align2, Color32, FontId, Painter, Pos2, Rect, Shape, Stroke};
use glam::{DMat3, DMat4, DVec2, DVec3};

use super::camera::{Camera, Projection};
use super::scene::{DrawnPose, Scene};
use super::style::{Badge, Palette, short_degrees};
use crate::analysis::shear_rgb;
use crate::eval::skinning::skin_shears;

/// Height of one caption line, in points.
const CAPTION_LINE: f32 = 17.0;

/// Width of the legend's column at the canvas's left, in points: its longest line with a margin; wider with the
/// ghost's entry or the painted skin's scale ("skin shear (most now: 18.7°)", the ramp's last label).
const LEGEND_WIDTH: f32 = 150.0;
const WIDE_LEGEND_WIDTH: f32 = 200.0;

/// Where the model is drawn inside a canvas `rect`: all of it, less a strip at the bottom for the caption when it
/// is shown, so the caption never covers the model.
pub fn drawing_rect(rect: Rect, scene: &Scene) -> Rect {
    if !scene.options.legend || scene.caption.is_empty() {
        return rect;
    }
    let strip = scene.caption.len() as f32 * CAPTION_LINE + 8.0;
    Rect::from_min_max(rect.min, Pos2::new(rect.max.x, (rect.max.y - strip).max(rect.min.y + rect.height() * 0.5)))
}

/// The column at the canvas's left that holds the legend (and, in the app, the messages at its foot), when the
/// legend is shown; at most half the canvas wide.
pub fn legend_rect(rect: Rect, scene: &Scene) -> Option<Rect> {
    let wide = scene.ghost.is_some() || shows_skin_scale(scene);
    let right = (rect.min.x + if wide { WIDE_LEGEND_WIDTH } else { LEGEND_WIDTH }).min(rect.center().x);
    scene.options.legend.then(|| Rect::from_min_max(rect.min, Pos2::new(right, rect.max.y)))
}

/// What the camera projects onto: the [`drawing_rect`] less the legend's column, so a framed figure stands
/// beside the legend, never under it (the grid still runs on under the legend). Framing and picking use the same
/// rectangle.
pub fn picture_rect(rect: Rect, scene: &Scene) -> Rect {
    let drawn = drawing_rect(rect, scene);
    match legend_rect(rect, scene) {
        Some(legend) => Rect::from_min_max(Pos2::new(legend.max.x, drawn.min.y), drawn.max),
        None => drawn,
    }
}

/// Paints `scene` into `rect` as seen by `camera` (the model in [`drawing_rect`], projected onto [`picture_rect`],
/// the legend in its column, the caption below).
pub fn paint(painter: &Painter, rect: Rect, camera: &Camera, scene: &Scene, palette: &Palette) {
    painter.rect_filled(rect, 0.0, palette.background);
    let (canvas, whole) = (painter.with_clip_rect(rect), rect);
    let projection = projection(camera, picture_rect(rect, scene));
    let painter = painter.with_clip_rect(drawing_rect(rect, scene));
    let options = &scene.options;
    if options.grid {
        paint_grid(&painter, &projection, scene, palette);
    }
    if options.bind_pose
        && let Some(bind) = &scene.bind_pose
    {
        let mut triangles = Vec::new();
        bone_triangles(&mut triangles, &projection, scene, bind, palette, camera, Some(palette.bind_pose));
        paint_sorted(&painter, triangles);
    }
    // The mesh is translucent and the bones are drawn over it (x-ray), so the skeleton is never hidden.
    let shears = options.paints_shear().then(|| skin_shears(scene.rig, &scene.primary.model));
    if options.mesh {
        let mut triangles = Vec::new();
        let color = |mesh: usize, vertex: usize| match &shears {
            Some(shears) => skin_color(scene, palette, shears[mesh][vertex]),
            None => palette.mesh,
        };
        mesh_triangles(&mut triangles, &projection, scene, &scene.primary, color, camera);
        paint_sorted(&painter, triangles);
    }
    let chain = scene.selected_chains();
    // The ghost goes under the pose, so the pose's colour coding reads on top and the ghost shows where they part.
    if let Some(ghost) = &scene.ghost {
        let mut ghost_triangles = Vec::new();
        if options.bones {
            bone_triangles(&mut ghost_triangles, &projection, scene, ghost, palette, camera, Some(palette.ghost));
        }
        paint_sorted(&painter, ghost_triangles);
        let faded = |c: Color32| c.gamma_multiply(0.45);
        if options.boxes {
            paint_boxes(&painter, &projection, scene, ghost, |bone| faded(box_color(ghost, bone, palette)));
        }
        paint_axes(&painter, &projection, scene, ghost, |bone| scene.shows_triad(ghost, &chain, bone), faded);
    }
    if options.bones {
        let mut triangles = Vec::new();
        bone_triangles(&mut triangles, &projection, scene, &scene.primary, palette, camera, None);
        paint_sorted(&painter, triangles);
    }
    if options.wireframe {
        paint_wireframe(&painter, &projection, scene, palette);
    }
    if options.boxes {
        let drawn = &scene.primary;
        paint_boxes(&painter, &projection, scene, drawn, |bone| box_color(drawn, bone, palette));
    }
    let primary = &scene.primary;
    paint_axes(&painter, &projection, scene, primary, |bone| scene.shows_triad(primary, &chain, bone), |c| c);
    paint_joints(&painter, &projection, scene, palette);
    if options.legend {
        let worst = shears.as_ref().filter(|_| shows_skin_scale(scene));
        let worst = worst.map(|shears| shears.iter().flatten().copied().fold(0.0, f64::max));
        if let Some(legend) = legend_rect(whole, scene) {
            paint_legend(&canvas, legend, scene, palette, worst);
        }
        paint_caption(&canvas, whole, &scene.caption, palette);
    }
}

/// The projection for a camera and a screen rectangle.
pub fn projection(camera: &Camera, rect: Rect) -> Projection {
    Projection::new(
        camera,
        DVec2::new(rect.min.x.into(), rect.min.y.into()),
        DVec2::new(rect.width().into(), rect.height().into()),
    )
}

fn pos(p: DVec2) -> Pos2 {
    Pos2::new(p.x as f32, p.y as f32)
}

fn screen(projection: &Projection, p: DVec3) -> Option<Pos2> {
    projection.project(p).map(|(s, _)| pos(s))
}

fn line(painter: &Painter, projection: &Projection, a: DVec3, b: DVec3, stroke: Stroke) {
    if let (Some(a), Some(b)) = (screen(projection, a), screen(projection, b)) {
        painter.line_segment([a, b], stroke);
    }
}

/// The bone a click at `at` hits: the nearest bone segment (or joint) within 10 points.
pub fn pick(scene: &Scene, camera: &Camera, rect: Rect, at: Pos2) -> Option<usize> {
    let projection = projection(camera, picture_rect(rect, scene));
    let at = glam::Vec2::new(at.x, at.y);
    let mut best: Option<(f32, usize)> = None;
    for bone in (0..scene.primary.model.len()).filter(|&b| scene.shows(b)) {
        let Some(head) = screen(&projection, scene.primary.head(bone)) else { continue };
        let head = glam::Vec2::new(head.x, head.y);
        let tail =
            scene.tail(&scene.primary, bone).and_then(|t| screen(&projection, t)).map(|t| glam::Vec2::new(t.x, t.y));
        let distance = match tail {
            Some(tail) => {
                let d = tail - head;
                let t = if d.length_squared() > 0.0 {
                    ((at - head).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (head + d * t).distance(at)
            }
            None => head.distance(at),
        };
        if distance <= 10.0 && best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, bone));
        }
    }
    best.map(|(_, bone)| bone)
}

fn paint_grid(painter: &Painter, projection: &Projection, scene: &Scene, palette: &Palette) {
    let radius = scene.bounds().map_or(2.0, |b| b.radius().max(b.center().length()));
    let step = nice_step(radius / 5.0);
    let lines = (radius * 1.5 / step).ceil() as i32;
    let extent = f64::from(lines) * step;
    for i in -lines..=lines {
        let c = f64::from(i) * step;
        let color = if i == 0 { palette.grid_axis } else { palette.grid };
        line(painter, projection, DVec3::new(c, 0.0, -extent), DVec3::new(c, 0.0, extent), Stroke::new(1.0, color));
        line(painter, projection, DVec3::new(-extent, 0.0, c), DVec3::new(extent, 0.0, c), Stroke::new(1.0, color));
    }
}

/// 1, 2 or 5 times a power of ten, at least `x`.
fn nice_step(x: f64) -> f64 {
    let power = 10f64.powf(x.max(1e-6).log10().floor());
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * power).find(|s| *s >= x).unwrap_or(10.0 * power)
}

/// A screen-space triangle with its depth and its corners' colours.
struct Triangle {
    points: [Pos2; 3],
    depth: f64,
    colors: [Color32; 3],
}

/// Flat shading: brighter where the face looks at the eye.
fn shade(color: Color32, normal: DVec3, toward_eye: DVec3) -> Color32 {
    let light = 0.45 + 0.55 * normal.dot(toward_eye).abs();
    let [r, g, b, a] = color.to_srgba_unmultiplied();
    let f = |c: u8| (f64::from(c) * light).round().clamp(0.0, 255.0) as u8;
    Color32::from_rgba_unmultiplied(f(r), f(g), f(b), a)
}

fn push_triangle(
    out: &mut Vec<Triangle>,
    projection: &Projection,
    corners: [DVec3; 3],
    colors: [Color32; 3],
    eye: DVec3,
) {
    let projected = corners.map(|c| projection.project(c));
    let [Some(a), Some(b), Some(c)] = projected else { return };
    let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize_or_zero();
    let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
    let toward_eye = (eye - centre).normalize_or_zero();
    out.push(Triangle {
        points: [pos(a.0), pos(b.0), pos(c.0)],
        depth: (a.1 + b.1 + c.1) / 3.0,
        colors: colors.map(|color| shade(color, normal, toward_eye)),
    });
}

fn paint_sorted(painter: &Painter, mut triangles: Vec<Triangle>) {
    triangles.sort_by(|a, b| b.depth.total_cmp(&a.depth));
    let mut mesh = EguiMesh::default();
    for t in triangles {
        let base = mesh.vertices.len() as u32;
        for (p, color) in t.points.into_iter().zip(t.colors) {
            mesh.colored_vertex(p, color);
        }
        mesh.add_triangle(base, base + 1, base + 2);
    }
    painter.add(Shape::mesh(mesh));
}

/// The meshes' triangles, each corner coloured by `color_of(mesh, vertex)`.
fn mesh_triangles(
    out: &mut Vec<Triangle>,
    projection: &Projection,
    scene: &Scene,
    drawn: &DrawnPose,
    color_of: impl Fn(usize, usize) -> Color32,
    camera: &Camera,
) {
    let eye = camera.eye();
    for (index, (mesh, positions)) in scene.rig.meshes.iter().zip(&drawn.meshes).enumerate() {
        for tri in mesh.indices.chunks_exact(3) {
            let corner = |i: u32| positions.get(i as usize).copied();
            if let (Some(a), Some(b), Some(c)) = (corner(tri[0]), corner(tri[1]), corner(tri[2])) {
                let colors = [tri[0], tri[1], tri[2]].map(|i| color_of(index, i as usize));
                push_triangle(out, projection, [a, b, c], colors, eye);
            }
        }
    }
}

/// A skin vertex's colour for its shear: the mesh's own below [`Scene::neutral_shear_deg`], else the shear ramp
/// of stretched bones ([`shear_rgb`]), as translucent as the mesh.
fn skin_color(scene: &Scene, palette: &Palette, shear_deg: f64) -> Color32 {
    if shear_deg < scene.neutral_shear_deg {
        return palette.mesh;
    }
    let [r, g, b] = shear_rgb(shear_deg);
    Color32::from_rgba_unmultiplied(r, g, b, SKIN_ALPHA)
}

/// How opaque the painted skin is: more than the plain mesh, so that its colours read, and still see-through, so
/// that the bones inside show.
const SKIN_ALPHA: u8 = 150;

/// The colour of a bone: selection first, then its most serious finding.
fn bone_color(scene: &Scene, drawn: &DrawnPose, bone: usize, palette: &Palette) -> Color32 {
    if scene.selected.contains(&bone) { palette.selected } else { drawn.finding_color(bone).unwrap_or(palette.bone) }
}

/// Octahedral bones from head to tail: a waist at a fifth of the length, a tenth as wide as long, oriented by the
/// bone's own X axis so twists show.
fn bone_triangles(
    out: &mut Vec<Triangle>,
    projection: &Projection,
    scene: &Scene,
    drawn: &DrawnPose,
    palette: &Palette,
    camera: &Camera,
    tint: Option<Color32>,
) {
    let eye = camera.eye();
    for bone in (0..drawn.model.len()).filter(|&b| scene.shows(b)) {
        let head = drawn.head(bone);
        let Some(tail) = scene.tail(drawn, bone) else { continue };
        let along = tail - head;
        let length = along.length();
        if length < 1e-9 {
            continue;
        }
        let axis = along / length;
        let reference = drawn.model[bone].x_axis.truncate();
        let reference = if reference.cross(axis).length() > 1e-6 { reference } else { axis.any_orthonormal_vector() };
        let u = (reference - axis * reference.dot(axis)).normalize() * length * 0.1;
        let v = axis.cross(u.normalize()) * length * 0.1;
        let waist = head + along * 0.2;
        let ring = [waist + u, waist + v, waist - u, waist - v];
        let color = tint.unwrap_or_else(|| bone_color(scene, drawn, bone, palette));
        for i in 0..4 {
            let (a, b) = (ring[i], ring[(i + 1) % 4]);
            push_triangle(out, projection, [head, b, a], [color; 3], eye);
            push_triangle(out, projection, [a, b, tail], [color; 3], eye);
        }
    }
}

fn paint_wireframe(painter: &Painter, projection: &Projection, scene: &Scene, palette: &Palette) {
    let stroke = Stroke::new(0.6, palette.text.gamma_multiply(0.35));
    for (mesh, positions) in scene.rig.meshes.iter().zip(&scene.primary.meshes) {
        let screen_positions: Vec<Option<Pos2>> = positions.iter().map(|p| screen(projection, *p)).collect();
        for tri in mesh.indices.chunks_exact(3) {
            for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                if let (Some(Some(a)), Some(Some(b))) =
                    (screen_positions.get(a as usize), screen_positions.get(b as usize))
                {
                    painter.line_segment([*a, *b], stroke);
                }
            }
        }
    }
}

/// A bone's box colour: its most important finding's, else the bone colour, faded.
fn box_color(drawn: &DrawnPose, bone: usize, palette: &Palette) -> Color32 {
    drawn.finding_color(bone).unwrap_or(palette.bone.gamma_multiply(0.6))
}

/// The smallest length, in points, axis triads and boxes are drawn with (at the rig's typical scale): like a DCC's
/// manipulators they stay readable however far the view is zoomed out.
const MIN_GIZMO: f64 = 16.0;

/// The longest a gizmo's axis is drawn, in gizmo lengths of the rig's typical scale: a bone scaled 100× (an
/// unconverted centimetre node, a bad export) keeps its triad beside its joint instead of across the view.
const MAX_GIZMO_STRETCH: f64 = 4.0;

/// The gizmo unit ([`Scene::gizmo_unit`]) for a joint at `at`: enlarged where a gizmo of the rig's typical scale
/// would be drawn shorter than [`MIN_GIZMO`], so a bone's own scale and shear still show in proportion.
fn gizmo_unit(scene: &Scene, projection: &Projection, at: DVec3) -> f64 {
    let drawn = projection.points_per_unit(at).map_or(0.0, |k| k * scene.gizmo_size);
    let enlarge = if drawn > 0.0 && drawn.is_finite() { (MIN_GIZMO / drawn).max(1.0) } else { 1.0 };
    scene.gizmo_unit * enlarge
}

/// A bone's gizmo axes in model space: its model matrix columns times [`gizmo_unit`], so their lengths show scale
/// and their angles shear, shrunk as a whole (angles and proportions kept) where the longest would pass
/// [`MAX_GIZMO_STRETCH`] typical lengths.
fn gizmo_axes(scene: &Scene, projection: &Projection, model: &DMat4) -> DMat3 {
    let unit = gizmo_unit(scene, projection, model.w_axis.truncate());
    let axes = DMat3::from_mat4(*model) * unit;
    let longest = [axes.x_axis, axes.y_axis, axes.z_axis].iter().map(|a| a.length()).fold(0.0, f64::max);
    let limit = MAX_GIZMO_STRETCH * unit * scene.gizmo_size / scene.gizmo_unit;
    if longest > limit && longest.is_finite() { axes * (limit / longest) } else { axes }
}

/// Each shown bone's gizmo axes ([`gizmo_axes`]) applied to a unit cube centred on the joint: shear slants it,
/// non-uniform scale stretches it.
fn paint_boxes(
    painter: &Painter,
    projection: &Projection,
    scene: &Scene,
    drawn: &DrawnPose,
    color_of: impl Fn(usize) -> Color32,
) {
    for (bone, model) in drawn.model.iter().enumerate().filter(|(b, _)| scene.shows(*b)) {
        let axes = gizmo_axes(scene, projection, model);
        let origin = model.w_axis.truncate();
        let corner = |i: usize| {
            let pick = |bit: usize| if i & bit == 0 { -0.5 } else { 0.5 };
            origin + axes * DVec3::new(pick(1), pick(2), pick(4))
        };
        let color = color_of(bone);
        for (a, b) in [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)] {
            line(painter, projection, corner(a), corner(b), Stroke::new(1.2, color));
        }
    }
}

/// A bone's triad in model space: its gizmo axes ([`gizmo_axes`]) scaled as a whole so that the longest is the
/// rig's gizmo length, whatever the bone's own scale (an `Empty` scaled 10 draws no lines across the view, a
/// squashed bone no dot): the angles and proportions that show shear and non-uniform scale stay.
fn triad_axes(scene: &Scene, projection: &Projection, model: &DMat4) -> DMat3 {
    let axes = gizmo_axes(scene, projection, model);
    let longest = [axes.x_axis, axes.y_axis, axes.z_axis].iter().map(|a| a.length()).fold(0.0, f64::max);
    let rig_size = gizmo_unit(scene, projection, model.w_axis.truncate()) * scene.gizmo_size / scene.gizmo_unit;
    if longest > 0.0 && longest.is_finite() { axes * (rig_size / longest) } else { axes }
}

/// Axis triads of the shown bones `which` picks ([`triad_axes`]).
fn paint_axes(
    painter: &Painter,
    projection: &Projection,
    scene: &Scene,
    drawn: &DrawnPose,
    which: impl Fn(usize) -> bool,
    tint: impl Fn(Color32) -> Color32,
) {
    let palette_axes = Palette::new(true).axes;
    for (_, model) in drawn.model.iter().enumerate().filter(|&(b, _)| scene.shows(b) && which(b)) {
        let origin = model.w_axis.truncate();
        let axes = triad_axes(scene, projection, model);
        for (axis, color) in [axes.x_axis, axes.y_axis, axes.z_axis].iter().zip(palette_axes) {
            line(painter, projection, origin, origin + *axis, Stroke::new(2.0, tint(color)));
        }
    }
}

fn paint_joints(painter: &Painter, projection: &Projection, scene: &Scene, palette: &Palette) {
    let drawn = &scene.primary;
    for bone in (0..drawn.model.len()).filter(|&b| scene.shows(b)) {
        let Some(p) = screen(projection, drawn.head(bone)) else { continue };
        let selected = scene.selected.contains(&bone);
        let color = bone_color(scene, drawn, bone, palette);
        painter.circle_filled(p, if selected { 5.0 } else { 3.5 }, color);
        if let Some(badge) = Badge::primary(&drawn.findings[bone]) {
            badge.paint_icon(painter, p + egui::vec2(9.0, -9.0), 4.5);
        }
        if scene.options.names || selected {
            let name = &scene.rig.skeleton.bone(bone).name;
            painter.text(p + egui::vec2(8.0, 4.0), Align2::LEFT_TOP, name, FontId::proportional(12.0), palette.text);
        }
    }
}

/// The meaning of the colours and icons, at the top of the legend's column `rect`; with `worst_skin_shear` (the
/// most any vertex shears now, in degrees) the painted skin's scale.
fn paint_legend(painter: &Painter, rect: Rect, scene: &Scene, palette: &Palette, worst_skin_shear: Option<f64>) {
    let mut at = rect.min + egui::vec2(14.0, 14.0);
    // Each entry beside its icon at `at`, wrapped within the column (a compared file's name can be long); the next
    // one goes below it.
    let entry = |at: &mut Pos2, text: &str| {
        let font = FontId::proportional(12.0);
        let galley = painter.layout(text.to_owned(), font, palette.text, (rect.right() - at.x - 14.0).max(40.0));
        let height = galley.size().y;
        painter.galley(*at + egui::vec2(10.0, -7.0), galley, palette.text);
        at.y += (height + 3.0).max(17.0);
    };
    for badge in Badge::ALL {
        badge.paint_icon(painter, at, 5.0);
        entry(&mut at, badge.label());
    }
    if scene.ghost.is_some() {
        painter.rect_filled(Rect::from_center_size(at, egui::vec2(9.0, 9.0)), 1.0, palette.ghost.to_opaque());
        entry(&mut at, &scene.ghost_label);
    }
    if let Some(worst) = worst_skin_shear {
        let top = at;
        entry(&mut at, &format!("skin shear (most now: {})", degrees(worst, scene.neutral_shear_deg)));
        paint_shear_scale(painter, Pos2::new(top.x, at.y - 3.0), scene, palette);
    }
}

/// Whether the legend has the painted skin's scale: where there is a skin painted by shear.
fn shows_skin_scale(scene: &Scene) -> bool {
    scene.options.paints_shear() && !scene.rig.meshes.is_empty()
}

/// A shear in degrees as the legend says it: two significant digits, 0 below the neutral shear.
fn degrees(shear_deg: f64, neutral: f64) -> String {
    if shear_deg < neutral { "0°".to_owned() } else { format!("{}°", short_degrees(shear_deg)) }
}

/// The painted skin's colours from `left`: a swatch of the neutral colour for no shear, then the ramp from 0.1° to
/// 10° (each decade half of it, as [`shear_rgb`] spreads it), labelled below.
fn paint_shear_scale(painter: &Painter, left: Pos2, scene: &Scene, palette: &Palette) {
    const WIDTH: f32 = 120.0;
    let neutral = Rect::from_min_size(left, egui::vec2(10.0, 8.0));
    // Apart enough that the labels "0" and "0.1°" below them do not touch.
    let bar = Rect::from_min_size(left + egui::vec2(30.0, 0.0), egui::vec2(WIDTH, 8.0));
    painter.rect_filled(neutral, 1.0, palette.mesh.to_opaque());
    let mut ramp = EguiMesh::default();
    for step in 0..=24 {
        let t = step as f32 / 24.0;
        let color = skin_color(scene, palette, 10f64.powf(f64::from(t) * 2.0 - 1.0)).to_opaque();
        ramp.colored_vertex(Pos2::new(bar.left() + t * WIDTH, bar.top()), color);
        ramp.colored_vertex(Pos2::new(bar.left() + t * WIDTH, bar.bottom()), color);
        if step > 0 {
            let base = ramp.vertices.len() as u32 - 4;
            ramp.add_triangle(base, base + 1, base + 2);
            ramp.add_triangle(base + 1, base + 2, base + 3);
        }
    }
    painter.add(Shape::mesh(ramp));
    let label = |x: f32, text: &str| {
        let at = Pos2::new(x, bar.bottom() + 2.0);
        painter.text(at, Align2::CENTER_TOP, text, FontId::proportional(10.0), palette.text)
    };
    label(neutral.center().x, "0");
    for (t, text) in [(0.0, "0.1°"), (0.5, "1°"), (1.0, "10°+")] {
        label(bar.left() + t * WIDTH, text);
    }
}

/// Right-aligned lines in the bottom right corner, clear of the legend at the top left however long they are.
fn paint_caption(painter: &Painter, rect: Rect, caption: &[String], palette: &Palette) {
    let mut at = Pos2::new(rect.max.x - 14.0, rect.max.y - 14.0);
    for text in caption.iter().rev() {
        painter.text(at, Align2::RIGHT_CENTER, text, FontId::proportional(12.0), palette.text);
        at.y -= CAPTION_LINE;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::demo_rig;
    use crate::view::{DrawnPose, SceneOptions};

    #[test]
    fn gizmos_keep_their_size_up_close_and_a_smallest_size_far_away() {
        // The demo rig's typical scale is 1: a triad of `unit` is `unit · points_per_unit` long on screen.
        let rig = demo_rig();
        let scene = Scene::new(&rig, DrawnPose::default(), SceneOptions::default());
        let rect = Rect::from_min_max(Pos2::ZERO, Pos2::new(400.0, 300.0));
        let at = DVec3::new(0.0, 1.5, 0.0);
        for (distance, on_screen) in [(2.0, None), (500.0, Some(MIN_GIZMO))] {
            let camera = Camera { distance, target: at, ..Camera::default() };
            let projection = projection(&camera, rect);
            let unit = gizmo_unit(&scene, &projection, at);
            let length = unit * projection.points_per_unit(at).unwrap();
            match on_screen {
                None => assert_eq!(unit, scene.gizmo_unit, "close up, the rig's own size ({length} points)"),
                Some(points) => assert!((length - points).abs() < 1e-9, "far away, {length} points"),
            }
        }
    }

    #[test]
    fn a_triad_shows_scale_in_proportion_but_never_leaves_its_joint() {
        let rig = demo_rig();
        let scene = Scene::new(&rig, DrawnPose::default(), SceneOptions::default());
        let rect = Rect::from_min_max(Pos2::ZERO, Pos2::new(400.0, 300.0));
        let at = DVec3::new(0.0, 1.5, 0.0);
        let camera = Camera { distance: 2.0, target: at, ..Camera::default() };
        let projection = projection(&camera, rect);
        let typical = gizmo_unit(&scene, &projection, at);
        let longest = |scale: DVec3| {
            let axes =
                gizmo_axes(&scene, &projection, &DMat4::from_scale_rotation_translation(scale, Default::default(), at));
            [axes.x_axis, axes.y_axis, axes.z_axis].map(|a| a.length() / typical)
        };
        assert_eq!(longest(DVec3::new(2.0, 1.0, 0.5)), [2.0, 1.0, 0.5], "scale shown as it is");
        let far = longest(DVec3::new(100.0, 50.0, 1.0));
        assert!((far[0] - MAX_GIZMO_STRETCH).abs() < 1e-12, "the longest axis capped: {far:?}");
        assert!((far[1] / far[0] - 0.5).abs() < 1e-12 && (far[2] / far[0] - 0.01).abs() < 1e-12, "proportions kept");
    }

    #[test]
    fn a_triad_is_drawn_at_the_rigs_size_whatever_the_bones_scale() {
        let rig = demo_rig();
        let scene = Scene::new(&rig, DrawnPose::default(), SceneOptions::default());
        let rect = Rect::from_min_max(Pos2::ZERO, Pos2::new(400.0, 300.0));
        let at = DVec3::new(0.0, 1.5, 0.0);
        let projection = projection(&Camera { distance: 2.0, target: at, ..Camera::default() }, rect);
        let rig_size = gizmo_unit(&scene, &projection, at) * scene.gizmo_size / scene.gizmo_unit;
        // An `Empty` scaled 10, a bone squashed to a hundredth, a stretched one: the longest axis is the rig's size,
        // the others in proportion.
        for scale in [DVec3::splat(10.0), DVec3::splat(0.01), DVec3::new(2.0, 1.0, 0.5)] {
            let model = DMat4::from_scale_rotation_translation(scale, Default::default(), at);
            let axes = triad_axes(&scene, &projection, &model);
            let lengths = [axes.x_axis, axes.y_axis, axes.z_axis].map(|a| a.length() / rig_size);
            let expected = (scale / scale.max_element()).to_array();
            for (length, expected) in lengths.iter().zip(expected) {
                assert!((length - expected).abs() < 1e-12, "scale {scale}: {lengths:?}");
            }
        }
    }

    #[test]
    fn the_caption_has_its_own_strip_below_the_model_and_the_legend_its_column() {
        let rig = demo_rig();
        let mut scene = Scene::new(&rig, DrawnPose::default(), SceneOptions::default());
        let rect = Rect::from_min_max(Pos2::ZERO, Pos2::new(400.0, 300.0));
        assert_eq!(drawing_rect(rect, &scene), rect, "no caption, the whole canvas");
        scene.caption = vec!["demo rig · stretch".into(), "0.500 s".into(), "mode: full".into()];
        assert_eq!(drawing_rect(rect, &scene).max.y, 300.0 - 3.0 * CAPTION_LINE - 8.0);
        // The camera projects beside the legend's column, so a framed figure is never under the legend.
        let legend = legend_rect(rect, &scene).unwrap();
        let picture = picture_rect(rect, &scene);
        assert_eq!((legend.min, legend.max.y), (rect.min, rect.max.y));
        assert_eq!((picture.min.x, picture.max), (legend.max.x, drawing_rect(rect, &scene).max));
        scene.options.legend = false;
        assert_eq!(picture_rect(rect, &scene), rect, "captions hidden with the legend, and its column");
        assert_eq!(legend_rect(rect, &scene), None);
    }
}
