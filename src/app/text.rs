//! Text that fits: numbers in a few characters without losing their size, names shortened in the middle (where
//! rigs' names differ: `Character1_LeftUpLeg` and `Character1_LeftLeg` share their start) with the full name on
//! hover.

use egui::{FontId, Response, RichText, Sense, TextStyle, Ui, WidgetText};

use crate::model::Clip;

/// The library's words in the app's font, which has no arrow: "forearm → segment-compensate" reads "forearm to
/// segment-compensate".
pub fn drawable(text: &str) -> String {
    text.replace('→', "to")
}

/// A clip as the pickers list it: its name and how long it plays, "walk (2.03 s)".
pub fn clip_choice(clip: &Clip) -> String {
    format!("{} ({:.2} s)", clip.label(), clip.span().length())
}

/// Below this a value is shown as 0, as the plots draw it: floating-point noise (a matrix's 5e-17, a fixed bone's
/// 6e-6° of shear left by single-precision keys), not a measurement.
const NOISE: f64 = 1e-5;

/// `x` as every number the app shows is taken: 0 where it is noise (never −0), else itself.
pub fn denoised(x: f64) -> f64 {
    if x.abs() < NOISE { 0.0 } else { x }
}

/// `x` in at most 7 characters with four or five significant digits: 4 decimals below 10, one fewer per digit
/// before the point, scientific notation from 100000 up and below 0.001 (so 3e-5 is not shown as 0.0000); noise
/// is 0 ([`denoised`]).
pub fn compact(x: f64) -> String {
    if !x.is_finite() {
        return "—".to_owned();
    }
    let x = denoised(x);
    let size = x.abs();
    if size == 0.0 {
        return "0".to_owned();
    }
    if !(1e-3..1e5).contains(&size) {
        return format!("{x:.1e}");
    }
    let digits_before = (size.log10().floor() as i32 + 1).max(1);
    let decimals = (5 - digits_before).clamp(0, 4) as usize;
    let text = format!("{x:.decimals$}");
    // 9.99996 rounds to "10.0000": one decimal too many for the width.
    if text.trim_start_matches('-').len() > 6 && decimals > 0 { format!("{x:.0$}", decimals - 1) } else { text }
}

/// `x` with every digit that is not noise, for a hover that gives the exact value: ten significant digits at most
/// (a double's seventeen say nothing its source, at best single precision, knew), trailing zeros dropped; noise
/// is 0 ([`denoised`]).
pub fn precise(x: f64) -> String {
    if !x.is_finite() {
        return "—".to_owned();
    }
    let x = denoised(x);
    if x == 0.0 {
        return "0".to_owned();
    }
    let decimals = (9 - x.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_owned() } else { text }
}

/// `text` with characters taken from its middle and replaced by "…" until `fits` says it fits; the whole text when
/// it does, "…" alone when nothing else fits.
pub fn shorten_middle(text: &str, fits: impl Fn(&str) -> bool) -> String {
    if fits(text) {
        return text.to_owned();
    }
    let chars: Vec<char> = text.chars().collect();
    // The most characters kept (half before the ellipsis, the rest after) that still fit.
    let (mut low, mut high) = (0, chars.len());
    while low < high {
        let keep = (low + high).div_ceil(2);
        if fits(&elide(&chars, keep)) {
            low = keep;
        } else {
            high = keep - 1;
        }
    }
    elide(&chars, low)
}

fn elide(chars: &[char], keep: usize) -> String {
    let head = keep.div_ceil(2);
    let tail = keep - head;
    chars[..head].iter().chain(['…'].iter()).chain(&chars[chars.len() - tail..]).collect()
}

/// A label of `name` no wider than `width` points, shortened in the middle when it has to be, with `full()` (the
/// full name, or more: a bone's path; made only while hovered) on hover where it says more than the label;
/// clickable and selectable like [`Ui::selectable_label`] when `selected` is given.
pub fn name_label(
    ui: &mut Ui,
    name: &str,
    full: impl FnOnce() -> String,
    width: f32,
    selected: Option<bool>,
) -> Response {
    let font = TextStyle::Button.resolve(ui.style());
    let padding = if selected.is_some() { 2.0 * ui.spacing().button_padding.x } else { 0.0 };
    let shown = shorten_middle(name, |text| text_width(ui, text, &font) + padding <= width);
    let response = match selected {
        Some(selected) => ui.add(egui::Button::selectable(selected, WidgetText::from(RichText::new(&shown)))),
        None => ui.add(egui::Label::new(&shown).sense(Sense::hover())),
    };
    if !response.hovered() {
        return response;
    }
    let full = full();
    if shown != full { response.on_hover_text(full) } else { response }
}

pub fn text_width(ui: &Ui, text: &str, font: &FontId) -> f32 {
    ui.fonts_mut(|fonts| fonts.layout_no_wrap(text.to_owned(), font.clone(), egui::Color32::WHITE).size().x)
}

/// A button showing `label`, as wide as `widest` would make it: a button whose label changes ("Play"/"Pause",
/// "Copy as JSON"/"Copied") keeps its width, so nothing beside or below it moves.
pub fn steady_button(ui: &Ui, label: &str, widest: &str) -> egui::Button<'static> {
    let width = text_width(ui, widest, &egui::TextStyle::Button.resolve(ui.style()));
    egui::Button::new(label.to_owned()).min_size(egui::vec2(width + 2.0 * ui.spacing().button_padding.x, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_their_size_in_seven_characters() {
        let cases = [
            (0.0, "0"),
            (1e-17, "0"),
            (std::f64::consts::FRAC_1_SQRT_2, "0.7071"),
            (-std::f64::consts::FRAC_1_SQRT_2, "-0.7071"),
            (12.34567, "12.346"),
            (-123.4567, "-123.46"),
            (1234.567, "1234.6"),
            (12345.67, "12346"),
            (123456.7, "1.2e5"),
            (3e-5, "3.0e-5"),
            (-4.77e-9, "0"),
            (6.4e-6, "0"),
            (9.99996, "10.000"),
            (f64::NAN, "—"),
        ];
        for (x, shown) in cases {
            assert_eq!(compact(x), shown, "{x}");
            assert!(compact(x).chars().count() <= 7);
        }
    }

    #[test]
    fn exact_values_keep_ten_digits_and_lose_their_noise() {
        let cases = [
            (5.060290082411953e-17, "0"),
            (-5.4e-6, "0"),
            (std::f64::consts::FRAC_1_SQRT_2, "0.7071067812"),
            (-123.4567, "-123.4567"),
            (1.0, "1"),
            (18.666049, "18.666049"),
            (123456789.123, "123456789.1"),
            (3e-5, "0.00003"),
            (f64::INFINITY, "—"),
        ];
        for (x, shown) in cases {
            assert_eq!(precise(x), shown, "{x}");
        }
    }

    #[test]
    fn names_lose_their_middle_to_fit() {
        let fits = |limit: usize| move |text: &str| text.chars().count() <= limit;
        assert_eq!(shorten_middle("forearm", fits(10)), "forearm");
        assert_eq!(shorten_middle("Character1_LeftUpLeg", fits(12)), "Charac…UpLeg");
        assert_eq!(shorten_middle("Character1_LeftUpLeg", fits(1)), "…");
        assert_eq!(shorten_middle("Character1_LeftUpLeg", fits(0)), "…", "nothing fits: the ellipsis alone");
    }
}
