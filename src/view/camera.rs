//! The viewport's camera: an orbit camera for the 3D view and orthographic front, side and top views.

use glam::dcamera::rh::{proj::opengl, view::look_at_mat4};
use glam::{DMat4, DVec2, DVec3, DVec4};

/// Which view the viewport shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ViewKind {
    /// 3D perspective with orbit.
    #[default]
    Persp,
    /// Orthographic, looking down −Z (X right, Y up).
    Front,
    /// Orthographic, looking down −X (Z right... from +X: −Z right, Y up).
    Side,
    /// Orthographic, looking down −Y (X right, −Z up).
    Top,
}

impl ViewKind {
    pub const ALL: [ViewKind; 4] = [ViewKind::Persp, ViewKind::Front, ViewKind::Side, ViewKind::Top];

    pub fn label(self) -> &'static str {
        match self {
            ViewKind::Persp => "Persp",
            ViewKind::Front => "Front",
            ViewKind::Side => "Side",
            ViewKind::Top => "Top",
        }
    }

    /// Direction from the target to the eye, and the screen's up, for the orthographic views.
    fn fixed_direction(self) -> Option<(DVec3, DVec3)> {
        match self {
            ViewKind::Persp => None,
            ViewKind::Front => Some((DVec3::Z, DVec3::Y)),
            ViewKind::Side => Some((DVec3::X, DVec3::Y)),
            ViewKind::Top => Some((DVec3::Y, -DVec3::Z)),
        }
    }
}

impl std::str::FromStr for ViewKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ViewKind::ALL
            .into_iter()
            .find(|v| v.label().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown view `{s}` (known: persp, front, side, top)"))
    }
}

/// Axis-aligned bounds of what should be in view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: DVec3,
    pub max: DVec3,
}

impl Bounds {
    /// The bounds of some points; `None` when there are none (or none finite).
    pub fn of(points: impl IntoIterator<Item = DVec3>) -> Option<Self> {
        points.into_iter().filter(|p| p.is_finite()).fold(None, |b: Option<Bounds>, p| {
            Some(b.map_or(Bounds { min: p, max: p }, |b| Bounds { min: b.min.min(p), max: b.max.max(p) }))
        })
    }

    pub fn union(self, other: Bounds) -> Bounds {
        Bounds { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the diagonal, at least a centimetre so a single point still frames.
    pub fn radius(&self) -> f64 {
        ((self.max - self.min).length() * 0.5).max(0.01)
    }

    /// The eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        let (min, max) = (self.min, self.max);
        std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        })
    }
}

/// Where the camera looks from. Angles in radians; `distance` in model units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub view: ViewKind,
    /// Turn about +Y; 0 looks down −Z (from the front).
    pub yaw: f64,
    /// Elevation above the horizon.
    pub pitch: f64,
    pub distance: f64,
    pub target: DVec3,
}

impl Default for Camera {
    fn default() -> Self {
        Camera { view: ViewKind::Persp, yaw: 0.6, pitch: 0.35, distance: 5.0, target: DVec3::new(1.0, 1.0, 0.0) }
    }
}

/// Vertical field of view of the perspective view.
const FOV_Y: f64 = 0.8;

/// The highest elevation of the orbit camera (just short of straight down, where "up" is undefined).
const MAX_PITCH: f64 = 1.55;

impl Camera {
    /// Moves the target to the centre of `bounds` and the eye back (or, in a 2D view, the zoom out) until every
    /// corner of them is inside a viewport of this aspect ratio (width / height), with a margin: the whole box
    /// fills the picture along its tighter side, whatever the view direction.
    pub fn frame(&mut self, bounds: &Bounds, aspect: f64) {
        self.frame_points(&bounds.corners(), aspect);
    }

    /// [`Camera::frame`] on the points themselves rather than their box: a figure over its motion (its joints and
    /// skin at times through the clip) fills the picture, where the corners of its box, most of them far from any
    /// part of it, would leave it small in the 3D view. The points are centred on the picture, not their box's
    /// centre (in perspective the near side looks larger, and a figure's raised arms put its middle above its
    /// box's): a few steps move the target until the margins either side match. Nothing happens for no finite
    /// point.
    pub fn frame_points(&mut self, points: &[DVec3], aspect: f64) {
        let points: Vec<DVec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
        let Some(bounds) = Bounds::of(points.iter().copied()) else { return };
        self.target = bounds.center();
        let (_, right, up) = self.basis();
        for _ in 0..4 {
            self.distance = self.fitting_distance(&points, aspect);
            let middle = self.middle_on_screen(&points);
            self.target += (right * middle.x + up * middle.y) * self.distance;
        }
        self.distance = self.fitting_distance(&points, aspect);
    }

    /// The distance (or, in a 2D view, the zoom) at which every point is in a picture of this aspect ratio, with
    /// a margin, the target staying where it is.
    fn fitting_distance(&self, points: &[DVec3], aspect: f64) -> f64 {
        const MARGIN: f64 = 1.15;
        let (back, right, up) = self.basis();
        let tan_y = (FOV_Y * 0.5).tan();
        let tan_x = tan_y * aspect.max(1e-3);
        let needed = points.iter().map(|point| {
            let d = *point - self.target;
            let (x, y) = (d.dot(right).abs() * MARGIN / tan_x, d.dot(up).abs() * MARGIN / tan_y);
            match self.view {
                // The point's depth in front of the eye, `distance − z`, must see it within the field of view.
                ViewKind::Persp => d.dot(back) + x.max(y),
                // 2D views show `distance·tan(fov/2)` either side of the target.
                _ => x.max(y),
            }
        });
        // At least a centimetre in view, so a single point still frames.
        needed.fold(0.01 * MARGIN / tan_y, f64::max)
    }

    /// The middle of the points' extent on screen (right, up), as a share of the distance: where the target
    /// should move, in distances, to have them centred.
    fn middle_on_screen(&self, points: &[DVec3]) -> DVec2 {
        let (back, right, up) = self.basis();
        let on_screen = points.iter().map(|point| {
            let d = *point - self.target;
            // Perspective divides by the depth in front of the eye; a 2D view by the distance alone.
            let depth = match self.view {
                ViewKind::Persp => (self.distance - d.dot(back)).max(1e-9),
                _ => self.distance,
            };
            DVec2::new(d.dot(right), d.dot(up)) / depth
        });
        let (min, max) = on_screen.fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        (min + max) * 0.5
    }

    /// Direction from the target to the eye, the screen's right and its up.
    fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let (back, up) = self.eye_direction();
        let right = up.cross(back).normalize();
        (back, right, back.cross(right))
    }

    /// Direction from the target to the eye, and up.
    fn eye_direction(&self) -> (DVec3, DVec3) {
        self.view.fixed_direction().unwrap_or_else(|| {
            let (sy, cy) = self.yaw.sin_cos();
            let (sp, cp) = self.pitch.sin_cos();
            (DVec3::new(cp * sy, sp, cp * cy), DVec3::Y)
        })
    }

    pub fn eye(&self) -> DVec3 {
        self.target + self.eye_direction().0 * self.distance
    }

    /// Model space → clip space for a viewport of the given aspect ratio (width / height).
    pub fn view_projection(&self, aspect: f64) -> DMat4 {
        let (direction, up) = self.eye_direction();
        let view = look_at_mat4(self.target + direction * self.distance, self.target, up);
        let far = self.distance * 20.0 + 100.0;
        let projection = match self.view {
            ViewKind::Persp => opengl::perspective(FOV_Y, aspect.max(1e-3), (self.distance * 0.01).max(1e-4), far),
            _ => {
                // The same extent as the perspective view has at the target, so switching views keeps the scale.
                let half_height = self.distance * (FOV_Y * 0.5).tan();
                let half_width = half_height * aspect;
                opengl::orthographic(-half_width, half_width, -half_height, half_height, -far, far)
            }
        };
        projection * view
    }

    /// Turns the 3D camera by a drag of `delta` radians (x: yaw, y: pitch); a 2D view becomes 3D from its own
    /// direction, so the picture turns rather than jumps.
    pub fn orbit(&mut self, delta: DVec2) {
        if let Some((direction, _)) = self.view.fixed_direction() {
            self.yaw = direction.x.atan2(direction.z);
            self.pitch = direction.y.clamp(-1.0, 1.0).asin();
            self.view = ViewKind::Persp;
        }
        self.yaw -= delta.x;
        self.pitch = (self.pitch + delta.y).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the target in the view plane by a fraction of the visible height.
    pub fn pan(&mut self, delta: DVec2) {
        let (direction, up) = self.eye_direction();
        let right = up.cross(direction).normalize();
        let screen_up = direction.cross(right);
        let extent = self.distance * (FOV_Y * 0.5).tan() * 2.0;
        self.target += (-right * delta.x + screen_up * delta.y) * extent;
    }

    /// Zooms by a factor (> 1 moves closer).
    pub fn zoom(&mut self, factor: f64) {
        self.zoom_at(factor, DVec2::ZERO);
    }

    /// Zooms by a factor towards a point of the picture, `at` from its centre in fractions of its height (x right,
    /// y down): that point stays under the pointer, as in DCC viewports.
    pub fn zoom_at(&mut self, factor: f64, at: DVec2) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let before = self.distance;
        self.distance = (self.distance / factor).clamp(1e-3, 1e6);
        // The pointer's point on the target plane moves by the change of the visible extent; pan it back.
        self.pan(-at * (before / self.distance - 1.0));
    }
}

/// Projects model-space points into a screen rectangle.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    view_projection: DMat4,
    /// The screen's right in model space.
    right: DVec3,
    origin: DVec2,
    size: DVec2,
}

impl Projection {
    /// `origin` is the rectangle's top-left corner, `size` its width and height, in points.
    pub fn new(camera: &Camera, origin: DVec2, size: DVec2) -> Self {
        let aspect = if size.y > 0.0 { size.x / size.y } else { 1.0 };
        let (direction, up) = camera.eye_direction();
        let right = up.cross(direction).normalize_or_zero();
        Projection { view_projection: camera.view_projection(aspect), right, origin, size }
    }

    /// How long a model-space length of 1 at `p`, across the line of sight, is on screen, in points; `None` behind
    /// the eye. (Across the line of sight the perspective divide is the same at both ends, so this is exact.)
    pub fn points_per_unit(&self, p: DVec3) -> Option<f64> {
        let (a, _) = self.project(p)?;
        let (b, _) = self.project(p + self.right)?;
        Some(a.distance(b))
    }

    /// The screen position and depth (larger is farther) of `p`; `None` behind the eye.
    pub fn project(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let clip: DVec4 = self.view_projection * p.extend(1.0);
        if clip.w <= 1e-9 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        let screen = self.origin + DVec2::new((ndc.x + 1.0) * 0.5 * self.size.x, (1.0 - ndc.y) * 0.5 * self.size.y);
        Some((screen, ndc.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn projection(camera: &Camera) -> Projection {
        Projection::new(camera, DVec2::ZERO, DVec2::new(200.0, 100.0))
    }

    #[test]
    fn the_target_projects_to_the_centre_in_every_view() {
        for view in ViewKind::ALL {
            let camera = Camera { view, ..Camera::default() };
            let (p, _) = projection(&camera).project(camera.target).unwrap();
            assert!(p.abs_diff_eq(DVec2::new(100.0, 50.0), 1e-9), "{view:?}: {p}");
        }
    }

    #[test]
    fn front_view_maps_x_right_and_y_up() {
        let camera = Camera { view: ViewKind::Front, target: DVec3::ZERO, ..Camera::default() };
        let p = projection(&camera);
        let (right, _) = p.project(DVec3::X).unwrap();
        let (up, _) = p.project(DVec3::Y).unwrap();
        assert!(right.x > 100.0 && (right.y - 50.0).abs() < 1e-9);
        assert!(up.y < 50.0 && (up.x - 100.0).abs() < 1e-9);
    }

    #[test]
    fn framing_puts_the_bounds_in_view() {
        let bounds = Bounds { min: DVec3::new(-3.0, 0.0, -1.0), max: DVec3::new(5.0, 2.0, 1.0) };
        for view in ViewKind::ALL {
            let mut camera = Camera { view, yaw: 0.6, pitch: 0.35, ..Camera::default() };
            camera.frame(&bounds, 2.0);
            let p = projection(&camera);
            let screen: Vec<DVec2> = bounds.corners().into_iter().map(|c| p.project(c).unwrap().0).collect();
            for s in &screen {
                assert!((0.0..=200.0).contains(&s.x) && (0.0..=100.0).contains(&s.y), "{view:?}: {s}");
            }
            // Tight: along one side of the picture the box spans most of it (the margin is 15 %; in perspective the
            // near corners reach the edge while the far ones, smaller, stop short of the other).
            let span = |f: fn(&DVec2) -> f64| {
                let values: Vec<f64> = screen.iter().map(f).collect();
                values.iter().copied().fold(f64::MIN, f64::max) - values.iter().copied().fold(f64::MAX, f64::min)
            };
            let filled = (span(|s| s.x) / 200.0).max(span(|s| s.y) / 100.0);
            let tight = if view == ViewKind::Persp { 0.6 } else { 0.85 };
            assert!(filled > tight, "{view:?}: the box fills only {filled} of the picture");
        }
        assert!(Bounds::of([DVec3::NAN]).is_none());
    }

    #[test]
    fn framed_points_are_centred_on_the_picture() {
        // A figure with its arms out high (a T) seen from above: its box's centre is below its middle on screen.
        let figure = [DVec3::ZERO, DVec3::new(0.0, 1.8, 0.0), DVec3::new(-0.9, 1.5, 0.0), DVec3::new(0.9, 1.5, 0.0)];
        for view in ViewKind::ALL {
            let mut camera = Camera { view, yaw: 0.6, pitch: 0.35, ..Camera::default() };
            camera.frame_points(&figure, 2.0);
            let p = projection(&camera);
            let screen: Vec<DVec2> = figure.iter().map(|c| p.project(*c).unwrap().0).collect();
            let (min, max) =
                screen.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), s| (lo.min(*s), hi.max(*s)));
            let margins = [min.x, 200.0 - max.x, min.y, 100.0 - max.y];
            assert!(
                (margins[0] - margins[1]).abs() < 0.5 && (margins[2] - margins[3]).abs() < 0.5,
                "{view:?}: {margins:?}"
            );
            assert!(margins.iter().all(|m| *m >= 0.0), "{view:?}: {margins:?}");
        }
    }

    #[test]
    fn a_unit_across_the_line_of_sight_measures_what_the_field_of_view_gives() {
        // 100 points of height show 2·distance·tan(fov/2) at the target, in every view; in perspective a point
        // twice as far looks half as long, in the 2D views the same.
        let camera = Camera { yaw: 0.3, pitch: 0.2, ..Camera::default() };
        let visible = 2.0 * camera.distance * (FOV_Y * 0.5).tan();
        for view in ViewKind::ALL {
            let camera = Camera { view, ..camera };
            let p = projection(&camera);
            let at_target = p.points_per_unit(camera.target).unwrap();
            assert!((at_target - 100.0 / visible).abs() < 1e-9, "{view:?}: {at_target}");
            let (back, _) = camera.eye_direction();
            let farther = p.points_per_unit(camera.target - back * camera.distance).unwrap();
            let expected = if view == ViewKind::Persp { at_target / 2.0 } else { at_target };
            assert!((farther - expected).abs() < 1e-9, "{view:?}: {farther}");
        }
        let camera = Camera::default();
        assert_eq!(projection(&camera).points_per_unit(camera.eye() + (camera.eye() - camera.target)), None);
    }

    #[test]
    fn orbiting_a_fixed_view_starts_from_its_direction() {
        for view in [ViewKind::Front, ViewKind::Side, ViewKind::Top] {
            let fixed = Camera { view, ..Camera::default() };
            let mut orbited = fixed;
            orbited.orbit(DVec2::ZERO);
            assert_eq!(orbited.view, ViewKind::Persp);
            // The eye stays where the fixed view had it (Top within the orbit's highest elevation).
            let (a, b) = (fixed.eye() - fixed.target, orbited.eye() - orbited.target);
            assert!(a.angle_between(b) < 0.03, "{view:?}: {a} vs {b}");
        }
    }

    #[test]
    fn zooming_towards_the_pointer_keeps_its_point_under_it() {
        // A point on the target plane, a quarter of the picture's height right of and above the centre.
        for view in [ViewKind::Front, ViewKind::Persp] {
            let mut camera = Camera { view, yaw: 0.0, pitch: 0.0, ..Camera::default() };
            let size = DVec2::new(200.0, 100.0);
            let screen = size * 0.5 + DVec2::new(25.0, -25.0);
            let at = (screen - size * 0.5) / size.y;
            let height = camera.distance * (FOV_Y * 0.5).tan() * 2.0;
            let point = camera.target + DVec3::new(at.x, -at.y, 0.0) * height;
            let (before, _) = projection(&camera).project(point).unwrap();
            assert!(before.abs_diff_eq(screen, 1e-9), "{view:?}: {before}");
            camera.zoom_at(1.5, at);
            let (after, _) = projection(&camera).project(point).unwrap();
            assert!(after.abs_diff_eq(screen, 1e-9), "{view:?}: {after} vs {screen}");
            assert!((camera.distance - 5.0 / 1.5).abs() < 1e-12);
        }
    }
}
