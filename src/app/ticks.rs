//! Axis ticks at 1-2-5 steps, far enough apart to be labelled: the plots' time and value axes and the timeline's
//! ruler. Times are ticked in the timeline's unit (seconds, frames or ticks), so a 175 s clip reads 0, 20, 40 … s
//! or 0, 2000, 4000 … frames, never only "0" and "100".

use egui_plot::{GridInput, GridMark};

use super::settings::TimeUnit;
use crate::eval::layers::TICKS_PER_SECOND;

/// The smallest step of the form {1, 2, 5} × 10ⁿ that is at least `at_least` (positive and finite; else 1).
pub fn step_125(at_least: f64) -> f64 {
    if !(at_least.is_finite() && at_least > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(at_least.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&step| step >= at_least * (1.0 - 1e-12))
        .unwrap_or(decade * 10.0)
}

/// Marks every `major` (labelled) with lighter lines between them (not labelled: egui_plot labels a mark only
/// when its `step_size` is wide enough on screen), over `bounds`; `major` and the values in one unit.
fn marks(bounds: (f64, f64), major: f64) -> Vec<GridMark> {
    // 1 → 5 parts, 2 → 4 parts, 5 → 5 parts: the minor lines fall on round numbers too.
    let mantissa = major / 10f64.powf(major.log10().floor());
    let minor = major / if (mantissa - 2.0).abs() < 1e-9 { 4.0 } else { 5.0 };
    let (first, last) = ((bounds.0 / minor).ceil() as i64, (bounds.1 / minor).floor() as i64);
    // A degenerate range, or one too wide for its pixels, gets no marks rather than millions.
    if last < first || last - first > 10_000 {
        return Vec::new();
    }
    (first..=last)
        .map(|i| {
            let value = i as f64 * minor;
            let on_major = ((value / major).round() * major - value).abs() < minor * 1e-6;
            GridMark { value, step_size: if on_major { major } else { minor } }
        })
        .collect()
}

/// Points between labelled marks: enough for a label of a few characters across (times) or a line of text
/// (values).
pub const TIME_LABEL_POINTS: f64 = 70.0;
pub const VALUE_LABEL_POINTS: f64 = 26.0;
/// The closest value labels are drawn, in points: a line of text and a little air (the value axis draws every
/// label from here on at full strength).
pub const CLOSEST_VALUE_LABELS: f64 = 18.0;

/// The points per value unit of a plot axis, from egui_plot's base step (the value span of its minimum grid
/// spacing, which is 8 points unless set otherwise).
fn points_per_value(input: &GridInput) -> f64 {
    const GRID_SPACING_MIN: f64 = 8.0;
    GRID_SPACING_MIN / input.base_step_size.max(f64::MIN_POSITIVE)
}

/// The next smaller step of the form {1, 2, 5} × 10ⁿ below `step` (one of that form).
fn smaller_125(step: f64) -> f64 {
    let mantissa = step / 10f64.powf(step.log10().floor());
    // 1 → 0.5, 2 → 1, 5 → 2.
    step * if (mantissa - 5.0).abs() < 1e-9 { 0.4 } else { 0.5 }
}

/// The marks of a value axis: 1-2-5 steps at least [`VALUE_LABEL_POINTS`] apart, closer (down to
/// [`CLOSEST_VALUE_LABELS`]) where that labels fewer than three values: a short plot spanning −0.75…1.05 reads
/// −0.5, 0, 0.5, 1, not a lone 0 (the 1 at its top edge hidden).
pub fn value_marks(input: GridInput) -> Vec<GridMark> {
    let per_value = points_per_value(&input);
    let (lo, hi) = input.bounds;
    let labelled = |step: f64| (hi / step).floor() - (lo / step).ceil() + 1.0;
    let closest = step_125(CLOSEST_VALUE_LABELS / per_value);
    let mut major = step_125(VALUE_LABEL_POINTS / per_value);
    while labelled(major) < 3.0 && smaller_125(major) >= closest * (1.0 - 1e-12) {
        major = smaller_125(major);
    }
    marks(input.bounds, major)
}

/// Seconds per step of `unit` (a frame at `rate`, a tick, a second).
fn seconds_per_unit(unit: TimeUnit, rate: f64) -> f64 {
    match unit {
        TimeUnit::Seconds => 1.0,
        TimeUnit::Frames => 1.0 / rate,
        TimeUnit::Ticks => 1.0 / TICKS_PER_SECOND,
    }
}

/// The labelled step, in seconds, of a time axis drawn at `points_per_second`: 1-2-5 steps of `unit` (whole frames
/// and ticks: never less than one).
pub fn time_step(unit: TimeUnit, rate: f64, points_per_second: f64) -> f64 {
    let per_unit = seconds_per_unit(unit, rate);
    let units = TIME_LABEL_POINTS / (points_per_second * per_unit);
    let units = if unit == TimeUnit::Seconds { step_125(units) } else { step_125(units.max(1.0)) };
    units * per_unit
}

/// The marks of a plot's time axis (values in seconds) in `unit`.
pub fn time_marks(input: GridInput, unit: TimeUnit, rate: f64) -> Vec<GridMark> {
    let major = time_step(unit, rate, points_per_value(&input));
    marks(input.bounds, major)
}

/// A time axis label: the time of `seconds` in `unit`, with as many decimals as the step needs and no more.
pub fn time_label(seconds: f64, step_seconds: f64, unit: TimeUnit, rate: f64) -> String {
    let per_unit = seconds_per_unit(unit, rate);
    let (value, step) = (seconds / per_unit, step_seconds / per_unit);
    let decimals = (-step.log10().floor()).clamp(0.0, 6.0) as usize;
    format!("{:.decimals$}", value + 0.0)
}

/// A value axis label: as many decimals as the step needs.
pub fn value_label(value: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).clamp(0.0, 6.0) as usize;
    format!("{:.decimals$}", value + 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_one_two_five() {
        assert_eq!(step_125(0.7), 1.0);
        assert_eq!(step_125(1.0), 1.0);
        assert_eq!(step_125(1.3), 2.0);
        assert_eq!(step_125(3.0), 5.0);
        assert_eq!(step_125(6.0), 10.0);
        assert_eq!(step_125(0.013), 0.02);
        assert_eq!(step_125(0.0), 1.0);
        assert_eq!(step_125(f64::NAN), 1.0);
    }

    #[test]
    fn a_long_clip_has_a_labelled_tick_every_few_seconds_or_frames() {
        // 175 s over 1000 points: 5.7 points a second, a label every 70 points = 12.3 s → 20 s.
        let points_per_second = 1000.0 / 175.0;
        assert_eq!(time_step(TimeUnit::Seconds, 120.0, points_per_second), 20.0);
        // In frames at 120 fps: 1476 frames → 2000 frames.
        assert!((time_step(TimeUnit::Frames, 120.0, points_per_second) - 2000.0 / 120.0).abs() < 1e-12);
        // Zoomed in far, frames never step by less than one.
        assert_eq!(time_step(TimeUnit::Frames, 30.0, 1e5), 1.0 / 30.0);
        assert_eq!(time_label(40.0, 20.0, TimeUnit::Seconds, 30.0), "40");
        assert_eq!(time_label(0.25, 0.05, TimeUnit::Seconds, 30.0), "0.25");
        assert_eq!(time_label(2000.0 / 120.0, 2000.0 / 120.0, TimeUnit::Frames, 120.0), "2000");
    }

    #[test]
    fn marks_label_the_major_steps_and_line_the_minor_ones() {
        let marks = marks((-0.05, 1.05), 0.5);
        let majors: Vec<f64> = marks.iter().filter(|m| m.step_size == 0.5).map(|m| m.value).collect();
        assert_eq!(majors, [0.0, 0.5, 1.0]);
        assert_eq!(marks.len(), 11, "minor marks every 0.1");
        assert!(super::marks((0.0, 1e9), 1e-6).is_empty(), "too many marks: none");
    }

    #[test]
    fn a_short_plot_labels_several_values_not_a_lone_zero() {
        // A quaternion plot 80 points high spanning −0.75…1.05 (−0.6…0.9 padded): 26 points would be a step of 1
        // (0 and 1 only); steps of 0.5 label four values, still 22 points apart.
        let input = GridInput { bounds: (-0.75, 1.05), base_step_size: 1.8 / 80.0 * 8.0 };
        let labelled: Vec<f64> = value_marks(input).iter().filter(|m| m.step_size == 0.5).map(|m| m.value).collect();
        assert_eq!(labelled, [-0.5, 0.0, 0.5, 1.0]);
        // Never closer than a line of text: 40 points for the same span keep steps of 1.
        let input = GridInput { bounds: (-0.75, 1.05), base_step_size: 1.8 / 40.0 * 8.0 };
        assert!(value_marks(input).iter().all(|m| m.step_size >= 1.0 || m.step_size < 0.5));
        assert_eq!([1.0, 2.0, 5.0, 0.1].map(smaller_125), [0.5, 1.0, 2.0, 0.05]);
    }

    #[test]
    fn short_value_axes_get_several_labels() {
        // An angle plot 80 points high spanning 0..40°: labels every 26 points at least → 20° steps → 0, 20, 40.
        let input = GridInput { bounds: (0.0, 40.0), base_step_size: 40.0 / 80.0 * 8.0 };
        let labelled: Vec<f64> = value_marks(input).iter().filter(|m| m.step_size == 20.0).map(|m| m.value).collect();
        assert_eq!(labelled, [0.0, 20.0, 40.0]);
    }
}
