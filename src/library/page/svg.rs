//! The page's pictures, drawn from a [`Sketch`]: the figure from the front at its worst moment, each bone in the
//! app's shear colours, and a stretched bone's shear over the clip as a sparkline.

use maud::{Markup, html};

use crate::analysis::shear_rgb;
use crate::analysis::sketch::{SHEAR_STEP_DEG, STEPS, Sketch};

/// A bone the clip does not stretch there.
const NEUTRAL: &str = "#8a8f98";

/// The figure's picture, `size` pixels square, the worst bone (`worst`, named) ringed.
pub fn figure(sketch: &Sketch, worst: &str, size: u32) -> Markup {
    let [x0, y0, x1, y1] = sketch.frame;
    let side = (x1 - x0).max(y1 - y0);
    let steps = f64::from(STEPS);
    // The shorter side centred in the square.
    let offset = |length: f64| if side > 0.0 { ((steps - length / side * steps) / 2.0).round() as i32 } else { 0 };
    let (dx, dy) = (offset(x1 - x0), offset(y1 - y0));
    // Saturating: a report read back may come from anywhere.
    let at = |bone: &[i32; 4]| (bone[1].saturating_add(dx), STEPS.saturating_sub(bone[2].saturating_add(dy)));
    let margin = STEPS / 20;
    let view = format!("{} {} {} {}", -margin, -margin, STEPS + 2 * margin, STEPS + 2 * margin);
    let worst_at = sketch.bones.get(sketch.worst).map(at);
    html! {
        svg xmlns="http://www.w3.org/2000/svg" width=(size) height=(size) viewBox=(view) role="img" class="figure" {
            title { "the figure from the front at its worst moment; " (worst) " ringed" }
            @for bone in &sketch.bones {
                @if let Some(parent) = usize::try_from(bone[0]).ok().and_then(|p| sketch.bones.get(p)) {
                    @let ((x1, y1), (x2, y2)) = (at(parent), at(bone));
                    line x1=(x1) y1=(y1) x2=(x2) y2=(y2) stroke=(colour(parent[3])) stroke-width="14" stroke-linecap="round" {}
                }
            }
            @for bone in &sketch.bones {
                @let (x, y) = at(bone);
                circle cx=(x) cy=(y) r="16" fill=(colour(bone[3])) {}
            }
            @if let Some((x, y)) = worst_at {
                circle cx=(x) cy=(y) r="45" fill="none" stroke="#222" stroke-width="10" {}
            }
        }
    }
}

/// A stretched bone's shear over the clip, `width` × `height` pixels, its highest point marked.
pub fn sparkline(curve: &[u32], width: u32, height: u32) -> Markup {
    let highest = curve.iter().copied().max().unwrap_or(0);
    // Small shears are drawn against a degree, so rounding does not fill the box.
    let top = f64::from(highest).max(1.0 / SHEAR_STEP_DEG);
    let (w, h) = (f64::from(width), f64::from(height));
    let point = |i: usize, v: u32| {
        let x = if curve.len() > 1 { i as f64 / (curve.len() - 1) as f64 * (w - 4.0) + 2.0 } else { w / 2.0 };
        (x, h - 2.0 - f64::from(v) / top * (h - 4.0))
    };
    let points: Vec<String> =
        curve.iter().enumerate().map(|(i, &v)| point(i, v)).map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
    let peak = curve.iter().position(|&v| v == highest).map(|i| point(i, highest));
    html! {
        svg xmlns="http://www.w3.org/2000/svg" width=(width) height=(height) role="img" class="spark" {
            title { "shear over the clip, at most " (format!("{:.2}", f64::from(highest) * SHEAR_STEP_DEG)) "°" }
            polyline points=(points.join(" ")) fill="none" stroke=(colour(highest.try_into().unwrap_or(i32::MAX))) stroke-width="1.5" {}
            @if let Some((x, y)) = peak {
                circle cx=(format!("{x:.1}")) cy=(format!("{y:.1}")) r="2.5" fill=(colour(highest.try_into().unwrap_or(i32::MAX))) {}
            }
        }
    }
}

/// The colour of a shear in the sketch's steps: the app's for a stretched bone, neutral for none.
pub fn colour(shear_steps: i32) -> String {
    if shear_steps <= 0 { NEUTRAL.to_owned() } else { colour_of_degrees(f64::from(shear_steps) * SHEAR_STEP_DEG) }
}

/// The app's colour of a stretched bone shearing by `shear_deg`, as CSS.
pub fn colour_of_degrees(shear_deg: f64) -> String {
    let [r, g, b] = shear_rgb(shear_deg);
    format!("#{r:02x}{g:02x}{b:02x}")
}
