//! Play, pause, loop, speed, frame step, and the time bar: keyframe ticks of the selected bones and a strip that
//! marks when the selected bone (or, with nothing selected, any bone) is stretched.

use egui::{Color32, Rect, Sense, Stroke, pos2, vec2};

use super::panel::Shared;
use super::reduce::merge_spans;
use super::settings::TimeUnit;
use super::text::text_width;
use crate::model::{Clip, Span};
use crate::view::Badge;

pub fn ui(ui: &mut egui::Ui, shared: &mut Shared) {
    ui.add_space(4.0);
    ui.horizontal(|ui| controls(ui, shared));
    time_bar(ui, shared);
    ui.add_space(4.0);
}

/// The whole frame before or after `time` at `rate` (from between two frames, the nearer one in that direction;
/// from a frame, the next), within `span`. Frames count on the clip's own clock, frame `n` at `n / rate`: a clip
/// that starts at frame 1 steps to 2, 3 …
pub fn step_frame(time: f64, rate: f64, forward: bool, span: Span) -> f64 {
    // Times within a millionth of a frame of a frame are on it.
    const ON_FRAME: f64 = 1e-6;
    let rate = if rate.is_finite() && rate > 0.0 { rate } else { 30.0 };
    let frame = time * rate;
    let next = if forward { (frame + ON_FRAME).floor() + 1.0 } else { (frame - ON_FRAME).ceil() - 1.0 };
    span.clamp(next / rate)
}

/// The playback's clock: the seconds between frames while playing, measured from the frame that started playing, so
/// that the time spent paused or idle before it never counts (egui's frame time after an idle spell is the spell).
#[derive(Default)]
pub struct PlayClock {
    /// The input time of the last frame that played.
    last: Option<f64>,
}

/// The most one frame advances the clip: a longer stall (a hidden window, a debugger) skips no more than this.
const MAX_FRAME_SECONDS: f64 = 0.25;

impl PlayClock {
    /// The seconds to advance at input time `now`: 0 on the first frame of playing and while paused.
    pub fn tick(&mut self, now: f64, playing: bool) -> f64 {
        let previous = std::mem::replace(&mut self.last, playing.then_some(now));
        match previous {
            Some(previous) if playing => (now - previous).clamp(0.0, MAX_FRAME_SECONDS),
            _ => 0.0,
        }
    }
}

/// Play or pause; playing at the end of a clip that does not loop starts it again from its start.
pub fn toggle_play(playing: &mut bool, time: &mut f64, looping: bool, span: Span) {
    *playing = !*playing;
    if *playing && !looping && *time >= span.end {
        *time = span.start;
    }
}

/// Where `seconds` of playing take the clip from `time`, and whether it plays on: past the end a loop goes round
/// within the span (on from its start, what overran carried over), else playing stops at the end.
pub fn played(time: f64, seconds: f64, span: Span, looping: bool) -> (f64, bool) {
    let time = time + seconds;
    if time <= span.end {
        (time, true)
    } else if looping && span.length() > 0.0 {
        (span.start + (time - span.start) % span.length(), true)
    } else {
        (span.end, false)
    }
}

fn controls(ui: &mut egui::Ui, shared: &mut Shared) {
    let span = shared.doc.span();
    let rate = shared.doc.frame_rate();
    frame_button(ui, shared, "Previous frame", "← key", false, rate, span);
    let play_label = if *shared.playing { "Pause" } else { "Play" };
    let play = super::text::steady_button(ui, play_label, "Pause");
    if ui.add(play).on_hover_text("Space; Home and End go to the ends").clicked() {
        toggle_play(shared.playing, shared.time, shared.settings.looping, span);
    }
    frame_button(ui, shared, "Next frame", "→ key", true, rate, span);
    ui.checkbox(&mut shared.settings.looping, "Loop");
    ui.add(egui::DragValue::new(&mut shared.settings.speed).range(0.01..=10.0).speed(0.01).prefix("speed ×"));
    ui.separator();
    let unit = shared.settings.time_unit;
    time_field(ui, shared, unit, rate, span);
    length_label(ui, shared, unit, rate, span);
    let label = ui.label("in");
    egui::ComboBox::from_id_salt("time-unit")
        .selected_text(unit.label())
        .show_ui(ui, |ui| {
            for u in TimeUnit::ALL {
                ui.selectable_value(&mut shared.settings.time_unit, u, u.label());
            }
        })
        .response
        .labelled_by(label.id);
    frame_rate_field(ui, shared, rate);
    if let Some((done, total)) = shared.results.progress {
        ui.separator();
        let fraction = if total > 0 { done as f32 / total as f32 } else { 0.0 };
        ui.add(egui::ProgressBar::new(fraction).desired_width(140.0).text("analysing clip"));
    }
}

/// "of 2.0 s": the timeline's length, in a slot as wide as the longest any clip of the rig gives in any unit, so that
/// the unit picker after it stays put whatever the clip or the unit.
fn length_label(ui: &mut egui::Ui, shared: &Shared, unit: TimeUnit, rate: f64, span: Span) {
    let font = egui::TextStyle::Body.resolve(ui.style());
    let lengths = spans(shared, span).into_iter().map(|s| s.length());
    let texts = lengths.flat_map(|length| TimeUnit::ALL.map(|u| format!("of {}", u.format_length(length, rate))));
    let widest = texts.map(|text| text_width(ui, &text, &font)).fold(0.0, f32::max);
    let ends = format!("from {} to {}", unit.format(span.start, rate), unit.format(span.end, rate));
    let shown = ui.label(format!("of {}", unit.format_length(span.length(), rate))).on_hover_text(ends);
    ui.add_space((widest - shown.rect.width()).max(0.0));
}

fn frame_button(ui: &mut egui::Ui, shared: &mut Shared, label: &str, key: &str, forward: bool, rate: f64, span: Span) {
    if ui.button(label).on_hover_text(key).clicked() {
        *shared.playing = false;
        *shared.time = step_frame(*shared.time, rate, forward, span);
    }
}

/// The current time in the chosen unit, editable within the span: type a time, frame or tick (or drag to scrub).
fn time_field(ui: &mut egui::Ui, shared: &mut Shared, unit: TimeUnit, rate: f64, span: Span) {
    let width = time_field_width(ui, unit, rate, &spans(shared, span));
    let field = egui::DragValue::new(shared.time)
        .range(span.start..=span.end)
        .speed(span.length().max(1e-3) / 500.0)
        .min_size(vec2(width, ui.spacing().interact_size.y))
        .custom_formatter(move |seconds, _| unit.format(seconds, rate))
        .custom_parser(move |text| unit.parse(text, rate));
    let response = ui.add(field).on_hover_text("type a time, a frame or a tick in the chosen unit");
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::SpinButton, true, "current time"));
    if response.changed() {
        *shared.playing = false;
    }
}

/// As wide as the time field's widest text, so the controls after it hold still while the clip plays and when
/// another clip is chosen: either end of any of `spans` half a frame farther from 0 (the most digits, and a
/// frame's decimal).
fn time_field_width(ui: &egui::Ui, unit: TimeUnit, rate: f64, spans: &[Span]) -> f32 {
    let font = ui.style().drag_value_text_style.resolve(ui.style());
    let half_frame = 0.5 / rate;
    let ends = spans.iter().flat_map(|span| [span.start, span.end]);
    let widest =
        ends.map(|t| text_width(ui, &unit.format(t + half_frame.copysign(t), rate), &font)).fold(0.0, f32::max);
    widest + 2.0 * ui.spacing().button_padding.x
}

/// The timeline's `span` now and the span of every clip of the rig: what the controls that show a time or a length
/// keep room for.
fn spans(shared: &Shared, span: Span) -> Vec<Span> {
    shared.doc.rig.clips.iter().map(Clip::span).chain([span]).collect()
}

/// The timeline's frame rate: the clip's own (from its file), or one the user types; "file's rate" goes back.
fn frame_rate_field(ui: &mut egui::Ui, shared: &mut Shared, rate: f64) {
    let mut chosen = rate;
    // At most three decimals, none that are zeros: a BVH's 0.0083333 s frames read "120 fps", as 30 fps does.
    let field = egui::DragValue::new(&mut chosen).range(1.0..=1000.0).suffix(" fps");
    let field =
        field.custom_formatter(|fps, _| format!("{fps:.3}").trim_end_matches('0').trim_end_matches('.').to_owned());
    let response = ui.add(field);
    let source = if shared.doc.frame_rate_override.is_some() { "chosen here" } else { "the clip's own" };
    let response = response.on_hover_text(format!("frames per second of stepping and frame numbers ({source})"));
    if response.changed() {
        shared.doc.frame_rate_override = Some(chosen);
    }
    if shared.doc.frame_rate_override.is_some() && ui.small_button("file's rate").clicked() {
        shared.doc.frame_rate_override = None;
    }
}

const BAR_HEIGHT: f32 = 34.0;
const STRIP_HEIGHT: f32 = 6.0;

/// The time bar's scale: the span from the bar's left edge to its right.
#[derive(Clone, Copy)]
struct Bar {
    rect: Rect,
    span: Span,
}

impl Bar {
    /// Where `time` is drawn.
    fn x(self, time: f64) -> f32 {
        let length = self.span.length();
        let fraction = if length > 0.0 { ((time - self.span.start) / length) as f32 } else { 0.0 };
        self.rect.left() + fraction * self.rect.width()
    }

    /// The time at `x`.
    fn time(self, x: f32) -> f64 {
        self.span.start + f64::from((x - self.rect.left()) / self.rect.width().max(1.0)) * self.span.length()
    }

    /// Seconds a point of the bar covers.
    fn seconds_per_point(self) -> f64 {
        self.span.length() / f64::from(self.rect.width().max(1.0))
    }
}

fn time_bar(ui: &mut egui::Ui, shared: &mut Shared) {
    let (rect, response) = ui.allocate_exact_size(vec2(ui.available_width(), BAR_HEIGHT), Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Slider, true, "time bar"));
    let bar = Bar { rect, span: shared.doc.span() };
    let (unit, rate) = (shared.settings.time_unit, shared.doc.frame_rate());
    if (response.clicked() || response.dragged())
        && let Some(p) = response.interact_pointer_pos()
    {
        *shared.playing = false;
        *shared.time = bar.span.clamp(unit.snap(bar.time(p.x), rate));
    }
    // A drag scrubs smoothly, and where it is let go (or clicked) is a whole frame, whatever the unit: a pose
    // between frames is none the file has.
    if response.clicked() || response.drag_stopped() {
        *shared.time = bar.span.clamp(TimeUnit::Frames.snap(*shared.time, rate));
    }
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    painter.rect_filled(rect, 3.0, visuals.extreme_bg_color);
    ruler(&painter, bar, (unit, rate), visuals.weak_text_color());
    if let Some(clip) = shared.doc.clip() {
        key_ticks(&painter, rect, clip, shared.selection, visuals.text_color(), |t| bar.x(t));
    }
    stretch_strip(&painter, bar, shared);
    let x = bar.x(*shared.time);
    painter.line_segment([pos2(x, rect.top()), pos2(x, rect.bottom())], Stroke::new(2.0, visuals.selection.bg_fill));
}

/// The ruler: a labelled tick at 1-2-5 steps of the timeline's unit, on the clip's own clock (a clip from frame 1
/// is ticked at frames 10, 20 …, not at its start plus those).
fn ruler(painter: &egui::Painter, bar: Bar, (unit, rate): (TimeUnit, f64), color: Color32) {
    let (span, rect) = (bar.span, bar.rect);
    if span.length() <= 0.0 {
        return;
    }
    let step = super::ticks::time_step(unit, rate, f64::from(rect.width()) / span.length());
    let (first, last) = ((span.start / step - 1e-9).ceil() as i64, (span.end / step + 1e-9).floor() as i64);
    for i in first..=last {
        let t = i as f64 * step;
        let x = bar.x(t);
        painter.line_segment([pos2(x, rect.bottom() - 8.0), pos2(x, rect.bottom())], Stroke::new(1.0, color));
        painter.text(
            pos2(x + 2.0, rect.bottom() - 9.0),
            egui::Align2::LEFT_BOTTOM,
            super::ticks::time_label(t, step, unit, rate),
            egui::FontId::proportional(9.0),
            color,
        );
    }
}

/// Key times of the selected bones' tracks as short ticks at the top: one per pixel column that has a key, runs of
/// such columns as one bar (a key every frame of a long clip is a solid bar, drawn as one rectangle).
fn key_ticks(
    painter: &egui::Painter,
    rect: Rect,
    clip: &Clip,
    selection: &[usize],
    color: Color32,
    x_of: impl Fn(f64) -> f32,
) {
    let columns = rect.width().max(1.0) as usize;
    let mut keyed = vec![false; columns + 1];
    for tracks in selection.iter().filter_map(|&bone| clip.tracks_of(bone)) {
        let times = [
            tracks.translation.as_ref().map(|t| t.times()),
            tracks.rotation.as_ref().map(|t| t.times()),
            tracks.scale.as_ref().map(|t| t.times()),
        ];
        for &t in times.into_iter().flatten().flatten() {
            let column = (x_of(t) - rect.left()).round().clamp(0.0, columns as f32) as usize;
            keyed[column] = true;
        }
    }
    let mut column = 0;
    while column <= columns {
        if !keyed[column] {
            column += 1;
            continue;
        }
        let run = keyed[column..].iter().take_while(|&&k| k).count();
        let x0 = rect.left() + column as f32 - 0.5;
        // Keys on every pixel (a baked clip) read as a thin band, so single keys around it stay distinct.
        let (rows, shade) = if run > 3 { (4.0..=7.0, color.gamma_multiply(0.5)) } else { (2.0..=9.0, color) };
        painter.rect_filled(
            Rect::from_x_y_ranges(x0..=x0 + run as f32, rect.top() + rows.start()..=rect.top() + rows.end()),
            0.0,
            shade,
        );
        column += run;
    }
}

/// Stretched spans of the inspected bone (or of any bone) as a coloured strip, merged to what the pixels show.
fn stretch_strip(painter: &egui::Painter, bar: Bar, shared: &Shared) {
    let rect = bar.rect;
    // Between the key ticks (top) and the seconds labels (bottom), so neither is painted over.
    let strip = Rect::from_min_size(pos2(rect.left(), rect.top() + 11.0), vec2(rect.width(), STRIP_HEIGHT));
    for (from, to) in merge_spans(shared.stretched, bar.seconds_per_point()) {
        let (x0, x1) = (bar.x(from), bar.x(to));
        painter.rect_filled(
            Rect::from_x_y_ranges(x0..=x1.max(x0 + 1.0), strip.y_range()),
            0.0,
            Badge::Stretched.color(),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_steps_land_on_whole_frames() {
        let ten = Span::new(0.0, 10.0);
        // 120 Hz mocap: one press is one source frame.
        assert_eq!(step_frame(0.0, 120.0, true, ten), 1.0 / 120.0);
        // From between frames (a click at 17.98 frames of 30 fps), the next whole frame each way.
        let between = 17.98 / 30.0;
        assert_eq!(step_frame(between, 30.0, true, ten), 18.0 / 30.0);
        assert_eq!(step_frame(between, 30.0, false, ten), 17.0 / 30.0);
        // From a frame (up to rounding), the neighbours.
        let on = 18.0 / 30.0 + 1e-12;
        assert_eq!(step_frame(on, 30.0, true, ten), 19.0 / 30.0);
        assert_eq!(step_frame(on, 30.0, false, ten), 17.0 / 30.0);
        // Within the clip.
        assert_eq!(step_frame(0.0, 30.0, false, ten), 0.0);
        assert_eq!(step_frame(9.99, 30.0, true, ten), 10.0);
        // On the clip's own clock: from Blender's first frame (1/30 s) the next is frame 2, the previous none.
        let blender = Span::new(1.0 / 30.0, 2.0);
        assert_eq!(step_frame(1.0 / 30.0, 30.0, true, blender), 2.0 / 30.0);
        assert_eq!(step_frame(1.0 / 30.0, 30.0, false, blender), 1.0 / 30.0);
    }

    #[test]
    fn the_clock_counts_only_the_time_spent_playing() {
        let mut clock = PlayClock::default();
        assert_eq!(clock.tick(0.0, false), 0.0);
        // Idle for 3 s, then Play: the first frame adds nothing, the next its frame time.
        assert_eq!(clock.tick(3.0, true), 0.0);
        assert!((clock.tick(3.016, true) - 0.016).abs() < 1e-12);
        // Paused for 10 s, then playing again: nothing of the pause.
        assert_eq!(clock.tick(13.0, false), 0.0);
        assert_eq!(clock.tick(13.5, true), 0.0);
        assert_eq!(clock.tick(20.0, true), MAX_FRAME_SECONDS, "a stall skips at most a quarter second");
    }

    #[test]
    fn play_at_the_end_without_loop_starts_again() {
        let span = Span::new(0.5, 2.0);
        let (mut playing, mut time) = (false, 2.0);
        toggle_play(&mut playing, &mut time, false, span);
        assert_eq!((playing, time), (true, 0.5), "from the clip's start");
        let (mut playing, mut time) = (false, 2.0);
        toggle_play(&mut playing, &mut time, true, span);
        assert_eq!((playing, time), (true, 2.0), "a looping clip goes on from where it is");
        toggle_play(&mut playing, &mut time, false, span);
        assert_eq!((playing, time), (false, 2.0));
    }

    #[test]
    fn a_loop_goes_round_within_the_span() {
        let span = Span::new(0.5, 2.0);
        assert_eq!(played(1.0, 0.25, span, true), (1.25, true));
        // 0.25 s past the end: 0.25 s after the start, not 0.25 s after 0.
        assert_eq!(played(1.75, 0.5, span, true), (0.75, true));
        assert_eq!(played(1.75, 0.5, span, false), (2.0, false), "without a loop it stops at the end");
        assert_eq!(played(0.5, 0.1, Span::at(0.5), true), (0.5, false), "a single pose has nothing to loop");
    }
}
