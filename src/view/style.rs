//! The colours and icons of findings, used the same way in the viewport, the outliner and the plots.

use egui::{Color32, Painter, Pos2, Shape, Stroke, Vec2};

use crate::analysis::{Findings, STRETCHED_RGB, shear_rgb};

/// A finding as people see it: a colour and an icon.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Badge {
    Stretched,
    NonUniform,
    Mirrored,
    Degenerate,
}

impl Badge {
    pub const ALL: [Badge; 4] = [Badge::Stretched, Badge::NonUniform, Badge::Mirrored, Badge::Degenerate];

    pub fn color(self) -> Color32 {
        match self {
            Badge::Stretched => Color32::from_rgb(STRETCHED_RGB[0], STRETCHED_RGB[1], STRETCHED_RGB[2]),
            Badge::NonUniform => Color32::from_rgb(240, 170, 40),
            Badge::Mirrored => Color32::from_rgb(70, 150, 240),
            Badge::Degenerate => Color32::from_rgb(150, 150, 160),
        }
    }

    /// The colour of a finding of this severity: for a stretched bone, its shear angle's ([`shear_rgb`]); other
    /// findings have one colour.
    pub fn color_for_shear(self, shear_deg: f64) -> Color32 {
        if self != Badge::Stretched {
            return self.color();
        }
        let [r, g, b] = shear_rgb(shear_deg);
        Color32::from_rgb(r, g, b)
    }

    pub fn label(self) -> &'static str {
        match self {
            Badge::Stretched => "stretched (shear)",
            Badge::NonUniform => "non-uniform scale",
            Badge::Mirrored => "mirrored",
            Badge::Degenerate => "degenerate",
        }
    }

    pub fn explanation(self) -> &'static str {
        match self {
            Badge::Stretched => "scale along axes that are not the bone's own (U ≠ I): a TRS runtime cannot hold it",
            Badge::NonUniform => "unequal scale along the bone's own axes: representable as TRS",
            Badge::Mirrored => "negative determinant",
            Badge::Degenerate => "a scale factor is (nearly) zero",
        }
    }

    /// The badges of some findings, most serious first.
    pub fn of(findings: &Findings) -> impl Iterator<Item = Badge> + '_ {
        Badge::ALL.into_iter().filter(|b| b.applies(findings))
    }

    /// The most serious badge, which decides a bone's colour.
    pub fn primary(findings: &Findings) -> Option<Badge> {
        Badge::of(findings).next()
    }

    fn applies(self, f: &Findings) -> bool {
        match self {
            Badge::Stretched => f.stretched,
            Badge::NonUniform => f.non_uniform,
            Badge::Mirrored => f.mirrored,
            Badge::Degenerate => f.degenerate,
        }
    }

    /// The icon: a diamond, a triangle, a square or a crossed ring, so colour is not the only cue.
    pub fn paint_icon(self, painter: &Painter, center: Pos2, radius: f32) {
        let color = self.color();
        let outline = Stroke::new(1.0, Color32::from_black_alpha(140));
        let points = |corners: &[(f32, f32)]| -> Vec<Pos2> {
            corners.iter().map(|&(x, y)| center + Vec2::new(x, y) * radius).collect()
        };
        match self {
            Badge::Stretched => {
                painter.add(Shape::convex_polygon(
                    points(&[(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)]),
                    color,
                    outline,
                ));
            }
            Badge::NonUniform => {
                painter.add(Shape::convex_polygon(points(&[(0.0, -1.0), (0.95, 0.8), (-0.95, 0.8)]), color, outline));
            }
            Badge::Mirrored => {
                painter.add(Shape::convex_polygon(
                    points(&[(-0.8, -0.8), (0.8, -0.8), (0.8, 0.8), (-0.8, 0.8)]),
                    color,
                    outline,
                ));
            }
            Badge::Degenerate => {
                painter.circle_stroke(center, radius * 0.85, Stroke::new(2.0, color));
                painter.line_segment(
                    [center + Vec2::splat(-0.6 * radius), center + Vec2::splat(0.6 * radius)],
                    Stroke::new(2.0, color),
                );
            }
        }
    }
}

/// An angle in degrees as the outliner's "max" note and the skin's legend give it: one decimal from 1° up, below
/// that two significant digits (a bone flagged at 0.043° must not read "0.0°", as if nothing sheared).
pub fn short_degrees(degrees: f64) -> String {
    if !(degrees > 0.0 && degrees < 1.0) {
        return format!("{degrees:.1}");
    }
    let decimals = (1 - degrees.log10().floor() as i32).clamp(1, 12) as usize;
    format!("{degrees:.decimals$}")
}

/// Colours of the viewport that do not depend on findings.
#[derive(Clone, Copy, Debug)]
pub struct Palette {
    pub background: Color32,
    pub grid: Color32,
    pub grid_axis: Color32,
    pub bone: Color32,
    pub selected: Color32,
    pub mesh: Color32,
    pub ghost: Color32,
    pub bind_pose: Color32,
    pub text: Color32,
    pub axes: [Color32; 3],
}

impl Palette {
    pub fn new(dark: bool) -> Self {
        let axes = [Color32::from_rgb(230, 70, 70), Color32::from_rgb(80, 200, 90), Color32::from_rgb(80, 130, 240)];
        if dark {
            Palette {
                background: Color32::from_rgb(30, 32, 36),
                grid: Color32::from_rgb(52, 55, 62),
                grid_axis: Color32::from_rgb(80, 84, 94),
                bone: Color32::from_rgb(185, 192, 206),
                selected: Color32::from_rgb(255, 230, 90),
                mesh: Color32::from_rgba_unmultiplied(120, 150, 170, 110),
                ghost: Color32::from_rgba_unmultiplied(120, 220, 255, 90),
                // Violet: apart from the bones' grey, the ghost's cyan and the selection's yellow, and bright enough to read
                // on the dark background.
                bind_pose: Color32::from_rgba_unmultiplied(190, 140, 255, 150),
                text: Color32::from_rgb(225, 228, 235),
                axes,
            }
        } else {
            Palette {
                background: Color32::from_rgb(236, 238, 242),
                grid: Color32::from_rgb(212, 215, 222),
                grid_axis: Color32::from_rgb(170, 175, 186),
                bone: Color32::from_rgb(90, 98, 115),
                selected: Color32::from_rgb(205, 140, 0),
                mesh: Color32::from_rgba_unmultiplied(120, 150, 175, 110),
                ghost: Color32::from_rgba_unmultiplied(0, 130, 200, 90),
                bind_pose: Color32::from_rgba_unmultiplied(95, 40, 165, 190),
                text: Color32::from_rgb(30, 32, 36),
                axes,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// WCAG's contrast ratio of `color` painted over `background` (alpha blended in sRGB, as egui blends).
    fn contrast(color: Color32, background: Color32) -> f64 {
        let [r, g, b, a] = color.to_srgba_unmultiplied().map(|c| f64::from(c) / 255.0);
        let [br, bg, bb, _] = background.to_srgba_unmultiplied().map(|c| f64::from(c) / 255.0);
        let over = [r * a + br * (1.0 - a), g * a + bg * (1.0 - a), b * a + bb * (1.0 - a)];
        let luminance = |[r, g, b]: [f64; 3]| {
            let linear = |c: f64| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
            0.2126 * linear(r) + 0.7152 * linear(g) + 0.0722 * linear(b)
        };
        let (l1, l2) = (luminance(over), luminance([br, bg, bb]));
        (l1.max(l2) + 0.05) / (l1.min(l2) + 0.05)
    }

    #[test]
    fn a_small_worst_shear_keeps_its_digits() {
        assert_eq!(short_degrees(24.26), "24.3");
        assert_eq!(short_degrees(0.5), "0.50");
        assert_eq!(short_degrees(0.0432), "0.043");
        assert_eq!(short_degrees(0.000_012_3), "0.000012");
    }

    #[test]
    fn the_bind_pose_reads_on_either_theme() {
        // 3:1 is WCAG's least contrast for graphics that must be made out.
        for dark in [true, false] {
            let palette = Palette::new(dark);
            let ratio = contrast(palette.bind_pose, palette.background);
            assert!(ratio >= 3.0, "dark {dark}: {ratio:.2}");
        }
    }
}
