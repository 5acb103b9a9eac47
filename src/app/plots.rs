//! Each decomposed component of the selected bones over the whole clip, in local or model space, under the
//! current modes and optionally the ghost mode. A cursor marks the current time; a click seeks. Several components
//! stack, one plot per unit, in a column that scrolls (and says so) when they outgrow the panel.
//!
//! Long clips stay smooth: curves are reduced to the minimum and maximum of each pixel column of the visible
//! range (see `reduce`) and drawn as a filled envelope at least a pixel thick; zoomed in far enough that every
//! sample has its own pixels, they are drawn as lines through the samples.

use egui::{Color32, RichText, Ui};
use egui_plot::{FilledArea, Line, Plot, PlotPoint, PlotPoints, VLine};
use glam::{EulerRot, Quat};

use super::document::Ghost;
use super::pane::{Pane, Place};
use super::panel::{Panel, Shared};
use super::settings::RotationFormat;
use super::work::ComparedCurves;
use std::sync::Arc;

use super::reduce::{Reduced, merge_spans, reduce};
use super::ticks;
use crate::analysis::{ClipAnalysis, Components};
use crate::view::Badge;

/// A curve's name and how to read it from a sample.
type Channel = (&'static str, fn(&Components) -> f64);

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Component {
    Translation,
    Rotation,
    Scale,
    Stretch,
    Sign,
    /// What bonescope is for: a bone selected shows its shear over the clip first.
    #[default]
    Shear,
}

impl Component {
    const ALL: [Component; 6] = [
        Component::Translation,
        Component::Rotation,
        Component::Scale,
        Component::Stretch,
        Component::Sign,
        Component::Shear,
    ];

    fn label(self) -> &'static str {
        match self {
            Component::Translation => "translation",
            Component::Rotation => "rotation",
            Component::Scale => "scale k",
            Component::Stretch => "stretch U",
            Component::Sign => "sign f",
            Component::Shear => "shear°",
        }
    }

    /// Channel names and how to read each from a sample.
    fn channels(self, format: RotationFormat) -> Vec<Channel> {
        match self {
            Component::Translation => vec![
                ("x", |c| c.translation.x.into()),
                ("y", |c| c.translation.y.into()),
                ("z", |c| c.translation.z.into()),
            ],
            Component::Rotation => match format {
                RotationFormat::Quaternion => vec![
                    ("x", |c| c.rotation.x.into()),
                    ("y", |c| c.rotation.y.into()),
                    ("z", |c| c.rotation.z.into()),
                    ("w", |c| c.rotation.w.into()),
                ],
                RotationFormat::Euler => vec![
                    ("X°", |c| euler(c.rotation).0),
                    ("Y°", |c| euler(c.rotation).1),
                    ("Z°", |c| euler(c.rotation).2),
                ],
                RotationFormat::AxisAngle => vec![
                    ("angle°", |c| axis_angle(c.rotation).0),
                    ("axis x", |c| axis_angle(c.rotation).1[0]),
                    ("axis y", |c| axis_angle(c.rotation).1[1]),
                    ("axis z", |c| axis_angle(c.rotation).1[2]),
                ],
            },
            Component::Scale => {
                vec![("x", |c| c.scale.x.into()), ("y", |c| c.scale.y.into()), ("z", |c| c.scale.z.into())]
            }
            Component::Stretch => vec![
                ("angle°", |c| axis_angle(c.stretch).0),
                ("axis x", |c| axis_angle(c.stretch).1[0]),
                ("axis y", |c| axis_angle(c.stretch).1[1]),
                ("axis z", |c| axis_angle(c.stretch).1[2]),
            ],
            Component::Sign => vec![("f", |c| c.sign.into())],
            Component::Shear => vec![("shear°", |c| c.shear_deg.into())],
        }
    }
}

fn euler(q: Quat) -> (f64, f64, f64) {
    let (x, y, z) = q.to_euler(EulerRot::XYZ);
    (f64::from(x.to_degrees()), f64::from(y.to_degrees()), f64::from(z.to_degrees()))
}

/// Angle in degrees and unit axis (the X axis for no rotation).
fn axis_angle(q: Quat) -> (f64, [f64; 3]) {
    let (axis, angle) = q.to_axis_angle();
    let axis = if axis.is_finite() && axis.length_squared() > 0.0 { axis } else { glam::Vec3::X };
    (f64::from(angle.to_degrees()), axis.as_dvec3().to_array())
}

pub struct Plots {
    /// The components plotted, in [`Component::ALL`]'s order: a click shows one, Ctrl- or Shift-click adds or removes.
    components: Vec<Component>,
    /// The curves, split into plots of one unit each (an angle in degrees and a unit axis never share an axis).
    cache: Option<(SeriesKey, Vec<Group>)>,
    /// Set by "Reset view": the next frame fits the plots to the whole clip again.
    reset: bool,
}

impl Default for Plots {
    fn default() -> Self {
        Plots { components: vec![Component::default()], cache: None, reset: false }
    }
}

/// The shortest a plot is drawn, in points: below it the stack scrolls rather than squeezing every plot.
const MIN_PLOT_HEIGHT: f32 = 120.0;

/// The curves of one plot: all in one unit, with their value range and their reduction to the visible range.
struct Group {
    series: Vec<Series>,
    range: (f64, f64),
    reduced: Option<(ReducedKey, Vec<Drawn>)>,
}

impl Group {
    /// The series split by unit: angles apart from the rest (a ghost's with its own), in their order.
    fn split(series: Vec<Series>) -> Vec<Group> {
        let (degrees, other): (Vec<Series>, Vec<Series>) = series.into_iter().partition(|s| s.degrees);
        [degrees, other]
            .into_iter()
            .filter(|s| !s.is_empty())
            .map(|series| Group { range: value_range(&series), series, reduced: None })
            .collect()
    }
}

/// A reduced curve in the plot's own types, kept across frames.
enum Drawn {
    Line(Vec<PlotPoint>),
    Envelope { xs: Vec<f64>, lows: Vec<f64>, highs: Vec<f64> },
}

impl From<Reduced> for Drawn {
    fn from(reduced: Reduced) -> Self {
        match reduced {
            Reduced::Points(points) => Drawn::Line(points.into_iter().map(|[x, y]| PlotPoint::new(x, y)).collect()),
            Reduced::Envelope { xs, lows, highs } => Drawn::Envelope { xs, lows, highs },
        }
    }
}

/// What the curves' values depend on.
#[derive(Clone, Debug)]
struct SeriesKey {
    /// Held so its address identifies the analysis for as long as the cache lives.
    analysis: Arc<ClipAnalysis>,
    bones: Vec<usize>,
    components: Vec<Component>,
    format: RotationFormat,
    model_space: bool,
    ghost: bool,
    /// A compared file's curves, which stand for the ghost's when it is the ghost.
    compared: Option<Arc<ComparedCurves>>,
}

impl PartialEq for SeriesKey {
    /// The analyses by identity: comparing their contents would cost more than rebuilding the curves.
    fn eq(&self, other: &Self) -> bool {
        let same_compared = match (&self.compared, &other.compared) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (a, b) => a.is_none() && b.is_none(),
        };
        Arc::ptr_eq(&self.analysis, &other.analysis)
            && same_compared
            && (&self.bones, &self.components, self.format, self.model_space, self.ghost)
                == (&other.bones, &other.components, other.format, other.model_space, other.ghost)
    }
}

/// What the reduction to pixel columns depends on, besides the series.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ReducedKey {
    x_min: f64,
    x_max: f64,
    columns: usize,
}

/// One curve: its values at every sample time of the analysis.
struct Series {
    name: String,
    color: Color32,
    ghost: bool,
    /// An angle in degrees (its channel's name ends in `°`), plotted apart from unit values.
    degrees: bool,
    values: Vec<f64>,
}

impl Panel for Plots {
    fn pane(&self) -> Pane {
        Pane::named("Plots")
    }

    fn place(&self) -> Place {
        Place::Centre(0.36)
    }

    fn plots_curves(&self) -> bool {
        true
    }

    fn ui(&mut self, ui: &mut Ui, shared: &mut Shared) {
        self.toolbar(ui, shared);
        let plotted = shared.plotted();
        if plotted.is_empty() {
            ui.label(RichText::new("Select bones to plot their components over the clip.").weak());
            return;
        }
        if shared.doc.span().length() <= 0.0 {
            ui.label(RichText::new("One pose, no time to plot it over: the Inspector lists its values.").weak());
            return;
        }
        let Some(analysis) =
            shared.results.curves.as_ref().filter(|a| plotted.iter().all(|b| a.curves_of(*b).is_some()))
        else {
            ui.label(RichText::new("analysing the clip…").weak());
            return;
        };
        let key = SeriesKey {
            analysis: analysis.clone(),
            bones: plotted,
            components: self.components.clone(),
            format: shared.settings.rotation_format,
            model_space: shared.settings.plot_model_space,
            ghost: shared.settings.plot_ghost && shared.doc.ghost.is_some() && shared.settings.plot_model_space,
            compared: shared
                .results
                .compared_curves
                .as_ref()
                .filter(|_| shared.doc.ghost == Some(Ghost::Compared))
                .cloned(),
        };
        if self.cache.as_ref().is_none_or(|(k, _)| *k != key) {
            let groups = key
                .components
                .iter()
                .flat_map(|&component| Group::split(build_series(&key, component, &shared.doc.rig.skeleton)))
                .collect();
            self.cache = Some((key, groups));
        }
        let reset = std::mem::take(&mut self.reset);
        let Some((key, groups)) = &mut self.cache else { return };
        legend(ui, groups);
        stack(ui, shared, key, groups, reset);
    }
}

impl Plots {
    /// The plot's controls, each in its place whatever is chosen (a control that does not apply is disabled, not
    /// hidden), so nothing moves under the pointer.
    fn toolbar(&mut self, ui: &mut Ui, shared: &mut Shared) {
        ui.horizontal_wrapped(|ui| {
            for c in Component::ALL {
                let shown = self.components.contains(&c);
                let response = ui
                    .selectable_label(shown, c.label())
                    .on_hover_text("Ctrl- or Shift-click to plot it with the others");
                if response.clicked() {
                    let adding = ui.input(|i| i.modifiers.command || i.modifiers.shift);
                    self.components = choose(&self.components, c, adding);
                }
            }
            ui.separator();
            ui.selectable_value(&mut shared.settings.plot_model_space, true, "model");
            ui.selectable_value(&mut shared.settings.plot_model_space, false, "local");
            ui.separator();
            let rotation = self.components.contains(&Component::Rotation);
            let format = &mut shared.settings.rotation_format;
            for (choice, label) in [
                (RotationFormat::Quaternion, "quaternion"),
                (RotationFormat::Euler, "Euler XYZ"),
                (RotationFormat::AxisAngle, "axis-angle"),
            ] {
                if ui.add_enabled(rotation, egui::Button::selectable(*format == choice, label)).clicked() {
                    *format = choice;
                }
            }
            ui.separator();
            ui.add_enabled(shared.doc.ghost.is_some(), egui::Checkbox::new(&mut shared.settings.plot_ghost, "ghost"))
                .on_disabled_hover_text("no ghost: choose one in the top bar");
            ui.separator();
            if ui.button("Reset view").on_hover_text("the whole clip again (or double-click a plot)").clicked() {
                self.reset = true;
            }
        });
    }
}

/// The components after a click on `clicked`: only it, or (`adding`) it added or removed, never none.
fn choose(shown: &[Component], clicked: Component, adding: bool) -> Vec<Component> {
    if !adding {
        return vec![clicked];
    }
    let toggled = |c: &Component| (*c == clicked) != shown.contains(c);
    let chosen: Vec<Component> = Component::ALL.into_iter().filter(toggled).collect();
    if chosen.is_empty() { vec![clicked] } else { chosen }
}

/// The plots one above the other, sharing the panel's height down to [`MIN_PLOT_HEIGHT`] each, in a column that
/// scrolls past that, its scroll bar drawn (not only on hover) and a line saying how many plots the column holds.
fn stack(ui: &mut Ui, shared: &mut Shared, key: &SeriesKey, groups: &mut [Group], reset: bool) {
    let count = groups.len();
    let spacing = ui.spacing().item_spacing.y;
    let fitting = (ui.available_height() + spacing) / count as f32 - spacing;
    // One plot takes whatever there is: scrolling it alone would show less of it, not more.
    let height = if count == 1 { fitting.max(MIN_PLOT_HEIGHT / 2.0) } else { fitting.max(MIN_PLOT_HEIGHT) };
    if count > 1 && fitting < MIN_PLOT_HEIGHT {
        ui.label(RichText::new(format!("{count} plots: the bar at the right scrolls to the rest")).weak());
    }
    let link = ui.scope_id().with("component-plots");
    // A solid bar where the column scrolls, drawn whether or not the pointer is near (egui's floating one hides
    // until hovered).
    ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
    egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
        for (index, group) in groups.iter_mut().enumerate() {
            plot(ui, shared, key, group, PlotPlace { index, last: index + 1 == count, height, reset, link });
        }
    });
}

/// The egui id of the `index`-th plot of the stack (its `egui_plot::PlotMemory` holds the visible range).
pub fn plot_id(index: usize) -> egui::Id {
    egui::Id::unique(("bonescope component plot", index))
}

/// Where one plot of the stack goes: its index, whether it carries the time axis, its height.
#[derive(Clone, Copy)]
struct PlotPlace {
    index: usize,
    last: bool,
    height: f32,
    reset: bool,
    /// Shared by the plots of the stack: their time axes and cursors move together.
    link: egui::Id,
}

/// The curves' names in their colours, in a row above the plots so no curve is hidden under a legend.
fn legend(ui: &mut Ui, groups: &[Group]) {
    ui.horizontal_wrapped(|ui| {
        for s in groups.iter().flat_map(|g| &g.series) {
            ui.label(RichText::new(&s.name).color(s.color).small());
        }
        ui.label(RichText::new("now").color(ui_cursor_color()).small());
    });
}

/// One plot of the stack: its curves reduced to the visible range, the stretched bands, the cursor. The wheel
/// zooms time about the pointer (all plots together, their time axes linked); a click seeks.
fn plot(ui: &mut Ui, shared: &mut Shared, key: &SeriesKey, group: &mut Group, place: PlotPlace) {
    let (time, stretched) = (*shared.time, shared.stretched);
    let (unit, rate) = (shared.settings.time_unit, shared.doc.frame_rate());
    let range = group.range;
    let response = frame(shared, &place, range).show(ui, |plot_ui| {
        let scroll = plot_ui.ctx().input(|i| i.smooth_scroll_delta.y);
        if plot_ui.response().hovered() && scroll != 0.0 {
            plot_ui.zoom_bounds_around_hovered(egui::Vec2::new((scroll * 0.0026).exp(), 1.0));
            plot_ui.set_auto_bounds(egui::Vec2b::new(false, true));
            // Taken: the column of plots around would scroll by it too.
            plot_ui.ctx().input_mut(|i| i.smooth_scroll_delta = egui::Vec2::ZERO);
        }
        curves(plot_ui, &key.analysis.times, group);
        stretched_bands(plot_ui, stretched, range);
        plot_ui.vline(VLine::new("now", time).color(ui_cursor_color()));
        plot_ui.pointer_coordinate()
    });
    if response.response.clicked()
        && let Some(at) = response.inner
    {
        *shared.playing = false;
        *shared.time = shared.doc.span().clamp(unit.snap(at.x, rate));
    }
}

/// The plot at `place`: the whole clip's time axis, on its own clock, in the chosen unit, linked to the other plots'
/// (the wheel zooms here, not egui_plot), reset when asked, and at least the curves' value range `(y_min, y_max)`
/// tall.
fn frame<'a>(shared: &Shared, place: &PlotPlace, (y_min, y_max): (f64, f64)) -> Plot<'a> {
    let span = shared.doc.span();
    let mut plot = Plot::new(("components", place.index))
        .id(plot_id(place.index))
        .height(place.height)
        // The curves are reduced to the visible range, so auto-bounds alone would never widen past it.
        .include_x(span.start)
        .include_x(span.end)
        // Never narrower than the value range (at least `MIN_SPAN`): rounding noise on a flat curve reads as flat.
        .include_y(y_min)
        .include_y(y_max)
        .link_axis(place.link, egui::Vec2b::new(true, false))
        .link_cursor(place.link, egui::Vec2b::new(true, false))
        .allow_scroll(false)
        .allow_zoom(false)
        .show_x(place.last)
        .allow_double_click_reset(true);
    let (unit, rate) = (shared.settings.time_unit, shared.doc.frame_rate());
    plot = plot
        .x_grid_spacer(move |input| ticks::time_marks(input, unit, rate))
        .y_grid_spacer(ticks::value_marks)
        .x_axis_formatter(move |mark, _| ticks::time_label(mark.value, mark.step_size, unit, rate))
        .custom_y_axes(vec![
            egui_plot::AxisHints::new_y()
                .formatter(|mark, _| ticks::value_label(mark.value, mark.step_size))
                // Every label the marks make is drawn, at full strength (egui_plot fades them below 30 points).
                .label_spacing((ticks::CLOSEST_VALUE_LABELS - 1.0) as f32..=ticks::CLOSEST_VALUE_LABELS as f32),
        ]);
    if place.last {
        plot = plot.x_axis_label(format!("time ({})", unit.label()));
    }
    if place.reset {
        plot = plot.reset();
    }
    plot
}

/// The group's curves over `times`, reduced to the visible range (kept until the range or the width changes): a
/// line where the samples are few enough, else an envelope at least a pixel thick.
fn curves<'a>(plot_ui: &mut egui_plot::PlotUi<'a>, times: &[f64], group: &'a mut Group) {
    let bounds = plot_ui.plot_bounds();
    let rect = plot_ui.response().rect;
    let reduced_key =
        ReducedKey { x_min: bounds.min()[0], x_max: bounds.max()[0], columns: rect.width().max(1.0) as usize };
    let (series, reduced_cache) = (&group.series, &mut group.reduced);
    if reduced_cache.as_ref().is_none_or(|(k, _)| *k != reduced_key) {
        let range = reduced_key.x_min..=reduced_key.x_max;
        let drawn =
            series.iter().map(|s| reduce(times, |i| s.values[i], range.clone(), reduced_key.columns).into()).collect();
        *reduced_cache = Some((reduced_key, drawn));
    }
    let drawn = reduced_cache.as_ref().map(|(_, d)| d.as_slice()).unwrap_or_default();
    // Half a pixel in plot units either side of an envelope keeps flat stretches visible.
    let half_pixel = 0.5 * (bounds.max()[1] - bounds.min()[1]) / f64::from(rect.height().max(1.0));
    for (s, drawn) in series.iter().zip(drawn) {
        match drawn {
            Drawn::Line(points) => {
                let line = Line::new(s.name.clone(), PlotPoints::Borrowed(points)).color(s.color);
                plot_ui.line(if s.ghost { line.style(egui_plot::LineStyle::dashed_loose()) } else { line });
            }
            Drawn::Envelope { xs, lows, highs } => {
                let lows: Vec<f64> = lows.iter().map(|v| v - half_pixel).collect();
                let highs: Vec<f64> = highs.iter().map(|v| v + half_pixel).collect();
                plot_ui.add(FilledArea::new(s.name.clone(), xs, &lows, &highs).fill_color(s.color));
            }
        }
    }
}

/// When the inspected bone is stretched, in the colour the viewport and outliner use for it. The bands span the
/// curves' own range `(y_min, y_max)`: spanning the plot's bounds would feed back into auto-bounds.
fn stretched_bands(plot_ui: &mut egui_plot::PlotUi, stretched: &[(f64, f64)], (y_min, y_max): (f64, f64)) {
    let bounds = plot_ui.plot_bounds();
    let pixel = (bounds.max()[0] - bounds.min()[0]) / f64::from(plot_ui.response().rect.width().max(1.0));
    for (from, to) in merge_spans(stretched, pixel) {
        let corners = vec![[from, y_min], [to, y_min], [to, y_max], [from, y_max]];
        plot_ui.polygon(
            egui_plot::Polygon::new("stretched", PlotPoints::from(corners))
                .fill_color(Badge::Stretched.color().gamma_multiply(0.12))
                .stroke(egui::Stroke::NONE),
        );
    }
}

/// The smallest value range a plot spans: a fix's 5e-6° of shear left is drawn as the 0 it is, not stretched to the
/// plot's height.
const MIN_SPAN: f64 = 0.02;

/// The smallest and largest value of all curves, padded by a tenth and at least [`MIN_SPAN`] apart (±1 when there
/// are none).
fn value_range(series: &[Series]) -> (f64, f64) {
    let values = series.iter().flat_map(|s| s.values.iter().copied()).filter(|v| v.is_finite());
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.1).max(0.5 * MIN_SPAN - 0.5 * (hi - lo)).max(0.0);
    (lo - pad, hi + pad)
}

/// Every curve of `component` at every sample, computed once per analysis and choice of components.
fn build_series(key: &SeriesKey, component: Component, skeleton: &crate::model::Skeleton) -> Vec<Series> {
    let channels = component.channels(key.format);
    let mut out = Vec::new();
    for (slot, &bone) in key.bones.iter().enumerate() {
        let Some(curves) = key.analysis.curves_of(bone) else { continue };
        let name = &skeleton.bone(bone).name;
        let primary = continuous(if key.model_space { &curves.model } else { &curves.local });
        let ghost = match &key.compared {
            // Only a compared curve of the same samples lines up with the document's.
            Some(compared) => compared.iter().find(|(b, _)| *b == bone).map(|(_, c)| c.as_slice()).unwrap_or(&[]),
            None => &curves.ghost_model,
        };
        let ghost = if key.ghost && ghost.len() == primary.len() { continuous(ghost) } else { Vec::new() };
        for (c, (channel, read)) in channels.iter().enumerate() {
            let color = channel_color(slot * channels.len() + c);
            // With other components beside it, a channel says whose it is ("hand scale k x", "hand shear°").
            let channel = match (key.components.len(), channels.len()) {
                (1, _) => (*channel).to_owned(),
                (_, 1) => component.label().to_owned(),
                _ => format!("{} {channel}", component.label()),
            };
            let degrees = channel.ends_with('°');
            out.push(Series {
                name: format!("{name} {channel}"),
                color,
                ghost: false,
                degrees,
                values: primary.iter().map(read).collect(),
            });
            if !ghost.is_empty() {
                let values = ghost.iter().map(read).collect();
                out.push(Series {
                    name: format!("{name} {channel} ({})", if key.compared.is_some() { "compared" } else { "ghost" }),
                    color: color.gamma_multiply(0.5),
                    ghost: true,
                    degrees,
                    values,
                });
            }
        }
    }
    out
}

fn ui_cursor_color() -> Color32 {
    Color32::from_rgb(255, 200, 60)
}

/// Quaternions flipped where needed so consecutive samples stay in one hemisphere: `q` and `−q` are the same
/// rotation, and the canonical `w ≥ 0` form would jump.
fn continuous(series: &[Components]) -> Vec<Components> {
    let mut out = series.to_vec();
    for i in 1..out.len() {
        if out[i].rotation.dot(out[i - 1].rotation) < 0.0 {
            out[i].rotation = -out[i].rotation;
        }
        if out[i].stretch.dot(out[i - 1].stretch) < 0.0 {
            out[i].stretch = -out[i].stretch;
        }
    }
    out
}

/// Distinct colours for the curves, in order (bone by bone, channel by channel).
fn channel_color(index: usize) -> Color32 {
    const COLORS: [Color32; 8] = [
        Color32::from_rgb(230, 80, 80),
        Color32::from_rgb(80, 190, 90),
        Color32::from_rgb(80, 140, 240),
        Color32::from_rgb(230, 170, 50),
        Color32::from_rgb(170, 100, 230),
        Color32::from_rgb(50, 200, 200),
        Color32::from_rgb(230, 110, 180),
        Color32::from_rgb(160, 160, 160),
    ];
    COLORS[index % COLORS.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(name: &str) -> Series {
        let degrees = name.ends_with('°');
        Series { name: name.to_owned(), color: Color32::WHITE, ghost: false, degrees, values: vec![0.0, 90.0] }
    }

    #[test]
    fn angles_and_unit_values_get_their_own_plots() {
        // Axis-angle: degrees in one plot, the unit axis in another (on one axis the axis curves would be flat).
        let groups = Group::split(["hand angle°", "hand axis x", "hand axis y", "hand axis z"].map(series).into());
        let names: Vec<Vec<&str>> = groups.iter().map(|g| g.series.iter().map(|s| s.name.as_str()).collect()).collect();
        assert_eq!(names, [vec!["hand angle°"], vec!["hand axis x", "hand axis y", "hand axis z"]]);
        // One unit: one plot.
        assert_eq!(Group::split(["hand x", "hand y"].map(series).into()).len(), 1);
        assert_eq!(Group::split(["hand X°", "hand Y°"].map(series).into()).len(), 1);
        // The ghost's curve (the shear before a fix tried) dashed over the curve itself.
        let ghost = Series { name: "hand shear° (ghost)".to_owned(), ghost: true, ..series("hand shear°") };
        assert_eq!(Group::split(vec![series("hand shear°"), ghost]).len(), 1);
    }

    #[test]
    fn a_flat_curve_with_rounding_noise_spans_the_smallest_range_and_reads_flat() {
        let noise = Series { values: vec![0.0, 5e-6, 0.0], ..series("forearm shear°") };
        let (lo, hi) = value_range(std::slice::from_ref(&noise));
        assert!((hi - lo - MIN_SPAN).abs() < 1e-12 && lo < 0.0 && hi > 5e-6, "({lo}, {hi})");
        // A curve that moves keeps a tenth of its span either side.
        assert_eq!(value_range(&[series("forearm shear°")]), (-9.0, 99.0));
    }
}
