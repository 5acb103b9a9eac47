//! The Inspector's Why? section, for a bone the whole-clip analysis flags: whose scale shears it (its chain at the
//! worst time, each bone's contribution), when (the main cause's time spans), and the fixes ranked
//! ([`crate::explain`]). A bone of the chain clicked is selected (shown in the viewport) while the Inspector stays
//! with the explained bone, a link away from it. The explanation is computed off the UI thread, one at a time (it cannot stop half way).
//!
//! A fix that is a setting of the document can be tried on it (one step of the history: Edit → Undo takes it back,
//! the ghost with it): a mode goes to the bone's own mode, a uniform scale to the layers.
//! The ghost then shows the clip as it was, beside the fixed pose, and the plots its curves dashed. While the fix
//! stands the section keeps the ranking it was chosen from (the bone no longer shears, so there would be nothing
//! to explain): the fix tried is marked with Undo beside it, and another is tried in its place.

use egui::collapsing_header::{CollapsingState, paint_default_icon};
use egui::{
    Align, Align2, Button, CollapsingHeader, Color32, Layout, Rect, RichText, Sense, Stroke, StrokeKind, TextStyle, Ui,
};
use egui::{pos2, vec2};
use std::sync::Arc;

use super::document::{Ghost, ModeScope};
use super::panel::Shared;
use super::text::{compact, denoised, drawable, name_label, text_width};
use crate::analysis::ScanOptions;
use crate::eval::Setup;
use crate::explain::{Change, Explanation, Fix, Link, Measured};
use crate::model::{Choice, ModeChoice, Unit};
use crate::view::Badge;

/// At most this many fixes are listed; the rest fold under "N more".
const SHOWN_FIXES: usize = 8;
/// At most this many time spans are listed; the rest fold under "N more".
const SHOWN_SPANS: usize = 6;

/// The bar of a bone whose squash counters the shear (a negative contribution): a colour no finding uses.
const COUNTERS: Color32 = Color32::from_rgb(60, 175, 160);

/// What the section keeps between frames.
#[derive(Default)]
pub struct Memory {
    /// The fix last tried, said in its place while it stands.
    tried: Option<Tried>,
    /// The bone whose section stays in the Inspector, and the bone of its chain clicked there, while that bone alone
    /// is selected.
    pinned: Option<(usize, usize)>,
}

/// A fix tried on a bone from this section: what was evaluated before it and after it (while the document still
/// evaluates that, it stands), the ranking it was chosen from, and the line that says what it did.
struct Tried {
    bone: usize,
    change: Change,
    /// Another fix is tried in this one's place on what was evaluated before.
    before: Setup,
    setup: Setup,
    explained: Arc<Explanation>,
    line: String,
}

/// The bone the Inspector shows: the selected one, or the bone in whose chain (in this section) the selected one was
/// clicked, for as long as that one alone is selected (any other selection lets the section go).
pub fn shown(shared: &Shared, memory: &mut Memory) -> Option<usize> {
    let selected = shared.inspected()?;
    let (selection, pinned) = (&shared.selection, &mut memory.pinned);
    *pinned = pinned.filter(|&(_, clicked)| selection.as_slice() == [clicked]);
    Some(pinned.map_or(selected, |(explained, _)| explained))
}

/// The line above a bone shown pinned ([`shown`]): which bone of its chain is selected (highlighted in the viewport,
/// its axes drawn, its curves plotted), and the way back to the bone itself.
pub fn pinned_line(ui: &mut Ui, shared: &mut Shared, bone: usize) {
    let Some(selected) = shared.inspected().filter(|&s| s != bone) else { return };
    let skeleton = &shared.doc.rig.skeleton;
    let (name, selected_name) = (skeleton.bone(bone).name.clone(), skeleton.bone(selected).name.clone());
    ui.label(RichText::new(drawable(&format!("{selected_name} selected: its scale shows in the viewport"))).weak());
    if ui.link(drawable(&format!("back to {name}"))).on_hover_text("select the explained bone again").clicked() {
        shared.select(bone, false);
    }
}

/// The section's header for `bone`, in the row of the Inspector's buttons (it takes no room of its own): a toggle
/// when the whole-clip analysis flags the bone, a note otherwise.
pub fn header(ui: &mut Ui, shared: &Shared, memory: &Memory, bone: usize) {
    match flagged(shared, bone) {
        None => {
            ui.label(RichText::new("Why? once the clip is analysed").weak());
        }
        Some(false) if standing(shared, memory, bone).is_none() => {
            ui.label(RichText::new("not sheared: nothing to explain").weak());
        }
        Some(_) => {
            let mut state = collapsing(ui.ctx());
            ui.horizontal(|ui| {
                ui.spacing_mut().item_spacing.x = 0.0;
                state.show_toggle_button(ui, paint_default_icon);
                let label = egui::Label::new(RichText::new("Why?").strong()).sense(Sense::click());
                if ui.add(label).on_hover_text("whose scale shears this bone, when, and the fixes").clicked() {
                    state.toggle(ui);
                }
            });
            state.store(ui.ctx());
        }
    }
}

/// The section's body, while its header is open: the explanation, computed off the UI thread; while a fix tried on
/// the bone stands, the line that says what it did over the ranking it was chosen from.
pub fn ui(ui: &mut Ui, shared: &mut Shared, memory: &mut Memory, bone: usize) {
    if let Some(tried) = standing(shared, memory, bone) {
        ui.label(RichText::new(&tried.line).strong());
        let explained = tried.explained.clone();
        collapsing(ui.ctx())
            .show_body_unindented(ui, |ui| ui.indent("why-body", |ui| explanation_ui(ui, shared, memory, &explained)));
        return;
    }
    if flagged(shared, bone) != Some(true) {
        return;
    }
    collapsing(ui.ctx()).show_body_unindented(ui, |ui| ui.indent("why-body", |ui| body(ui, shared, memory, bone)));
}

fn body(ui: &mut Ui, shared: &mut Shared, memory: &mut Memory, bone: usize) {
    // The flag above may be the previous state's: explain once the analysis of this one is there.
    if shared.results.progress.is_some() {
        spinner(ui, "waiting for the whole-clip analysis…");
        return;
    }
    let options = ScanOptions { rate: shared.doc.analysis_rate(), tolerances: shared.settings.tolerances };
    match shared.work.explanation(shared.doc, bone, options) {
        Some((explained, true)) => explanation_ui(ui, shared, memory, &explained),
        Some((first, false)) => first_answer_ui(ui, shared, memory, &first),
        None => spinner(ui, &format!("explaining {}…", shared.doc.rig.skeleton.bone(bone).name)),
    }
}

/// The fix tried on `bone`, while the document evaluates what it made.
fn standing<'a>(shared: &Shared, memory: &'a Memory, bone: usize) -> Option<&'a Tried> {
    memory.tried.as_ref().filter(|t| t.bone == bone && t.setup == *shared.doc.setup())
}

/// Whether the whole-clip analysis flags `bone` anywhere in the clip; `None` before the first analysis.
fn flagged(shared: &Shared, bone: usize) -> Option<bool> {
    Some(shared.results.analysis.as_ref()?.scan.bones.get(bone).is_some_and(|b| b.stretched()))
}

/// Opens the section (a file opened on its worst bone shows why at once).
pub fn open(ctx: &egui::Context) {
    let mut state = collapsing(ctx);
    state.set_open(true);
    state.store(ctx);
}

/// Whether the section is open: one state for every bone, so that it stays open while the selection changes.
fn collapsing(ctx: &egui::Context) -> CollapsingState {
    CollapsingState::load_with_default_open(ctx, egui::Id::unique("inspector-why"), false)
}

fn spinner(ui: &mut Ui, text: &str) {
    ui.horizontal(|ui| {
        ui.spinner();
        ui.label(RichText::new(text).weak());
    });
}

/// The explanation with its best fix alone, while every fix is ranked: the headline (the cause and that fix), the
/// chain and the causes over the clip.
fn first_answer_ui(ui: &mut Ui, shared: &mut Shared, memory: &mut Memory, first: &Explanation) {
    ui.label(drawable(&first.headline(shared.doc.rig.unit)));
    if first.causes.stretched_samples == 0 {
        return;
    }
    ui.add_space(4.0);
    chain(ui, shared, memory, first);
    ui.add_space(4.0);
    spans(ui, shared, first);
    ui.add_space(4.0);
    spinner(ui, "ranking every fix…");
}

fn explanation_ui(ui: &mut Ui, shared: &mut Shared, memory: &mut Memory, explained: &Arc<Explanation>) {
    ui.label(drawable(&explained.headline(shared.doc.rig.unit)));
    if explained.causes.stretched_samples == 0 {
        return;
    }
    for answer in explained.answers(shared.doc.rig.unit) {
        ui.label(RichText::new(drawable(&answer)).small());
    }
    ui.add_space(4.0);
    chain(ui, shared, memory, explained);
    ui.add_space(4.0);
    spans(ui, shared, explained);
    ui.add_space(4.0);
    fixes(ui, shared, memory, explained);
    for note in &explained.notes {
        ui.label(RichText::new(drawable(&format!("note: {note}"))).small().weak());
    }
}

/// The widths of a chain row's columns: the name, the bar, the contribution and the main-cause mark.
struct Columns {
    name: f32,
    bar: f32,
    mark: f32,
}

impl Columns {
    fn of(ui: &Ui) -> Columns {
        let spacing = ui.spacing().item_spacing.x;
        let number = text_width(ui, &format!("{:>8}°", ""), &TextStyle::Monospace.resolve(ui.style()));
        let mark = text_width(ui, "main", &TextStyle::Body.resolve(ui.style()));
        let available = ui.available_width();
        let name = (0.34 * available).clamp(60.0, 140.0);
        Columns { name, bar: (available - name - number - mark - 4.0 * spacing).max(24.0), mark }
    }
}

/// The chain at the worst time, root first: each bone's name (a click selects it, the section staying), a bar as long as the share of
/// the shear its squash causes, the contribution in degrees, and the scale where it is unequal.
fn chain(ui: &mut Ui, shared: &mut Shared, memory: &mut Memory, explained: &Explanation) {
    let at = &explained.causes.at;
    ui.horizontal_wrapped(|ui| {
        let hint = "each bone's contribution: the shear minus what is left with its scale made uniform (all else as \
                    evaluated); scales compound and cancel, so contributions need not add up";
        ui.label(RichText::new("Chain at").strong()).on_hover_text(hint);
        if ui.link(shared.time_text(at.time)).on_hover_text("go to the time the bone shears most").clicked() {
            go_to(shared, at.time);
        }
        let shear = RichText::new(format!("shear {}°", compact(at.shear_deg)));
        ui.label(shear).on_hover_text("the largest angle by which two of the bone's axes miss 90°");
    });
    let main = at.main_cause().map(|l| l.bone);
    let columns = Columns::of(ui);
    let tolerance = shared.settings.tolerances.min_anisotropy;
    for link in &at.chain {
        let pinned = &mut memory.pinned;
        link_row(ui, shared, pinned, explained.bone, link, at.shear_deg, Some(link.bone) == main, &columns);
        if link.anisotropy > tolerance {
            ui.horizontal(|ui| {
                ui.add_space(ui.spacing().indent);
                let k = link.scale;
                let turn = link.turn_deg.map_or_else(String::new, |t| format!(" · turned {}°", compact(t)));
                let text = format!("scale {} {} {}{turn}", compact(k.x), compact(k.y), compact(k.z));
                ui.label(text).on_hover_text(link_hint(link, at.shear_deg));
            });
        }
    }
    if !at.sufficient.is_empty() {
        let names: Vec<&str> = at.sufficient.iter().map(|&b| shared.doc.rig.skeleton.bone(b).name.as_str()).collect();
        let text = match names.as_slice() {
            [one] => format!("{one}'s scale made uniform alone unflags it"),
            _ => format!("{}'s scales made uniform together unflag it", names.join(" and ")),
        };
        ui.label(RichText::new(text).weak());
    }
}

/// One bone of `explained`'s chain; a click on its name selects it, the section staying with `explained` (`pinned`).
#[expect(clippy::too_many_arguments)]
fn link_row(
    ui: &mut Ui,
    shared: &mut Shared,
    pinned: &mut Option<(usize, usize)>,
    explained: usize,
    link: &Link,
    shear: f64,
    main: bool,
    columns: &Columns,
) {
    ui.horizontal(|ui| {
        let selected = shared.selection.contains(&link.bone);
        let name = name_label(ui, &link.name, || link.name.clone(), columns.name, Some(selected));
        let room = columns.name - name.rect.width();
        if name.clicked() {
            shared.select(link.bone, false);
            *pinned = Some((explained, link.bone)).filter(|_| link.bone != explained);
        }
        ui.add_space(room.max(0.0));
        let hint = link_hint(link, shear);
        bar(ui, columns.bar, link.contribution_deg, shear, main).on_hover_text(&hint);
        let number = RichText::new(format!("{:>7}°", compact(link.contribution_deg))).monospace();
        ui.label(number).on_hover_text(&hint);
        if main {
            let mark = RichText::new("main").strong().color(Badge::Stretched.color());
            ui.label(mark).on_hover_text("the main cause: its squash causes the most shear");
        } else {
            ui.add_space(columns.mark);
        }
    });
}

/// A bar `width` long, filled in proportion to `contribution / shear` (at most whole), in the shear's colour or,
/// for a squash that counters it, another; outlined for the main cause.
fn bar(ui: &mut Ui, width: f32, contribution: f64, shear: f64, main: bool) -> egui::Response {
    let (rect, response) = ui.allocate_exact_size(vec2(width, ui.spacing().interact_size.y), Sense::hover());
    let track = Rect::from_min_size(pos2(rect.left(), rect.center().y - 4.0), vec2(rect.width(), 8.0));
    let painter = ui.painter();
    painter.rect_filled(track, 2.0, ui.visuals().extreme_bg_color);
    let share = if shear > 0.0 { (contribution.abs() / shear).min(1.0) as f32 } else { 0.0 };
    let color = if contribution < 0.0 { COUNTERS } else { Badge::Stretched.color() };
    painter.rect_filled(Rect::from_min_size(track.min, vec2(track.width() * share, track.height())), 2.0, color);
    if main {
        painter.rect_stroke(track, 2.0, Stroke::new(1.0, ui.visuals().strong_text_color()), StrokeKind::Outside);
    }
    response
}

/// A chain bone's numbers, and what a negative contribution means: its scale counters the others'.
fn link_hint(link: &Link, shear: f64) -> String {
    let k = link.scale;
    let (x, y, z) = (compact(k.x), compact(k.y), compact(k.z));
    let mut text =
        format!("{}'s local scale ({x}, {y}, {z}), unequal by {} %", link.name, compact(100.0 * link.anisotropy));
    if let Some(turn) = link.turn_deg {
        text.push_str(&format!("; its axes turned {}° from the bone's", compact(turn)));
    }
    let (left, shear, causes) = (compact(link.shear_left_deg), compact(shear), compact(link.contribution_deg));
    text.push_str(&format!("\nmade uniform, {left}° of the {shear}° shear is left: it causes {causes}°"));
    if link.contribution_deg < 0.0 {
        text.push_str("\nnegative: its scale counters the others' (made uniform, the shear grows)");
    }
    text.push_str("\ncontributions need not add up: scales compound and cancel");
    text
}

/// The main cause's time spans: a click goes to the start of one.
fn spans(ui: &mut Ui, shared: &mut Shared, explained: &Explanation) {
    let spans = &explained.causes.spans;
    if spans.is_empty() {
        return;
    }
    ui.label(RichText::new("Main cause over the clip").strong());
    listed(ui, "why-more-spans", spans, SHOWN_SPANS, |ui, span| {
        let (from, to) = (shared.time_text(span.from), shared.time_text(span.to));
        let text = format!("{}  {from} – {to}", span.name);
        let hint = format!("go to {from}, where {}'s squash starts to be the main cause", span.name);
        if ui.link(text).on_hover_text(hint).clicked() {
            go_to(shared, span.from);
        }
    });
}

/// The fixes, best first: each with what it leaves and what it moves, in columns; a Try button on those that are
/// settings of the document.
fn fixes(ui: &mut Ui, shared: &mut Shared, memory: &mut Memory, explained: &Arc<Explanation>) {
    // Those that change something: Blender's Fix Shear on a bone its parent does not shear is no fix.
    let shown: Vec<&Fix> = explained.shown_fixes(false, shared.settings.tolerances.min_shear_deg).collect();
    if shown.is_empty() {
        return;
    }
    ui.label(RichText::new("Fixes, best first").strong());
    let unit = shared.doc.rig.unit;
    let columns = FixColumns::of(ui, &shown, unit);
    let row = |ui: &mut Ui, fix: &&Fix| fix_row(ui, shared, memory, fix, &columns, explained);
    listed(ui, "why-more-fixes", &shown, SHOWN_FIXES, row);
}

/// The widths of a fix's rows: the Try button (or Undo, in its place while its fix stands), and the widest effect and distance among the fixes (so that the
/// numbers of every fix line up).
struct FixColumns {
    button: f32,
    effect: f32,
    distance: f32,
    unit: Option<Unit>,
}

impl FixColumns {
    fn of(ui: &Ui, fixes: &[&Fix], unit: Option<Unit>) -> FixColumns {
        let body = TextStyle::Body.resolve(ui.style());
        let widest = |text: &dyn Fn(&Fix) -> String| {
            fixes.iter().map(|fix| text_width(ui, &text(fix), &body)).fold(0.0, f32::max)
        };
        FixColumns {
            button: text_width(ui, "Undo", &TextStyle::Button.resolve(ui.style()))
                + 2.0 * ui.spacing().button_padding.x,
            effect: widest(&effect),
            distance: widest(&|fix| distance(fix, unit)),
            unit,
        }
    }
}

/// One fix: the Try button (Undo while it is the fix tried; for a bake, where to make it), then its label over its
/// numbers.
fn fix_row(
    ui: &mut Ui,
    shared: &mut Shared,
    memory: &mut Memory,
    fix: &Fix,
    columns: &FixColumns,
    explained: &Arc<Explanation>,
) {
    let hint = fix_hint(fix, columns.unit, &shared.time_text(fix.cost.distance.time));
    let tried = memory.tried.as_ref().is_some_and(|t| t.change == fix.change && t.setup == *shared.doc.setup());
    ui.with_layout(Layout::left_to_right(Align::Min), |ui| {
        match fix.change {
            Change::Bake { strategy } => bake_slot(ui, strategy, columns.button),
            _ if tried => undo_button(ui, shared, columns.button),
            _ => try_button(ui, shared, memory, fix, columns, explained),
        }
        ui.vertical(|ui| {
            // Rows as tall as their text, so that the label and its numbers read as one entry.
            ui.spacing_mut().interact_size.y = 0.0;
            ui.spacing_mut().item_spacing.y = 1.0;
            let label = drawable(&fix.label);
            let label = RichText::new(if tried { format!("tried: {label}") } else { label });
            let label = if fix.removes || tried { label.strong() } else { label };
            ui.add(egui::Label::new(label).truncate()).on_hover_text(&hint);
            ui.horizontal_wrapped(|ui| {
                let effect = RichText::new(effect(fix));
                let effect = if fix.removes { effect } else { effect.color(Badge::Stretched.color()) };
                slot(ui, effect, columns.effect).on_hover_text(&hint);
                slot(ui, RichText::new(distance(fix, columns.unit)), columns.distance).on_hover_text(&hint);
                // Whole or on the next row, never broken in the middle.
                let share = format!("{} % of rig", compact(100.0 * fix.cost.fraction));
                ui.add(egui::Label::new(share).extend()).on_hover_text(&hint);
            });
            if !fix.newly_flagged().is_empty() {
                let text = format!("shears {}", fix.newly_flagged().join(", "));
                let text = RichText::new(text).color(Badge::Stretched.color());
                ui.add(egui::Label::new(text).wrap())
                    .on_hover_text("bones the analysis flags with the fix, not before");
            }
        });
    });
}

/// Try: the fix made (in place of the one tried, while that stands: one step of the history, not two), said in the
/// section's place, and the timeline at the bone's worst time, where it shows.
fn try_button(
    ui: &mut Ui,
    shared: &mut Shared,
    memory: &mut Memory,
    fix: &Fix,
    columns: &FixColumns,
    explained: &Arc<Explanation>,
) {
    let what = match fix.change {
        Change::UniformScale { .. } => "adds the uniform scale to the layers (remove it in the Layers panel)",
        _ => "sets the bone's mode (set it back from the skeleton's menu, or Declared in the toolbar)",
    };
    let hint = format!("{what}; the ghost then shows the clip as it was");
    if !ui.add(Button::new("Try").small().min_size(vec2(columns.button, 0.0))).on_hover_text(hint).clicked() {
        return;
    }
    let standing = memory.tried.take().filter(|t| t.setup == *shared.doc.setup());
    let before = match standing {
        Some(tried) if shared.doc.set_setup(tried.before.clone()).is_ok() => {
            *shared.step_in_place = true;
            tried.before
        }
        _ => shared.doc.setup().clone(),
    };
    try_fix(shared, fix.change);
    go_to(shared, explained.causes.at.time);
    let setup = shared.doc.setup().clone();
    let line = tried_line(fix, explained, columns.unit, &shared.time_text(fix.cost.distance.time));
    let explained = explained.clone();
    memory.tried = Some(Tried { bone: explained.bone, change: fix.change, before, setup, explained, line });
}

/// Undo, in the Try button's place while its fix stands: the fix taken back (Edit → Undo).
fn undo_button(ui: &mut Ui, shared: &mut Shared, width: f32) {
    let button = Button::selectable(true, "Undo").small().min_size(vec2(width, 0.0));
    if ui.add(button).on_hover_text("take the fix back (Edit → Undo)").clicked() {
        *shared.undo_asked = true;
    }
}

/// "Tried: forearm to blender-aligned: shear 18.666° before, 0° after; skin moved 11 cm at 0.5667 s (frame 17)",
/// the time (`when`) as the timeline shows it.
fn tried_line(fix: &Fix, explained: &Explanation, unit: Option<Unit>, when: &str) -> String {
    let moved = match fix.cost.measured {
        Measured::Skin => "skin",
        Measured::Bones => "bones",
    };
    let distance = fix.cost.distance;
    format!(
        "Tried: {}: shear {}° before, {}° after; {moved} moved {} at {when}",
        drawable(&fix.label),
        compact(explained.worst_shear_deg),
        compact(if fix.removes { 0.0 } else { fix.shear_left_deg }),
        Unit::readable(unit, distance.max),
    )
}

/// A bake is a new file, not a setting of the document: where the Try button would be, the command that makes it.
fn bake_slot(ui: &mut Ui, strategy: crate::bake::Strategy, width: f32) {
    let (rect, response) = ui.allocate_exact_size(vec2(width, ui.spacing().interact_size.y), Sense::hover());
    let font = TextStyle::Body.resolve(ui.style());
    ui.painter().text(rect.center(), Align2::CENTER_CENTER, "CLI", font, ui.visuals().weak_text_color());
    response.on_hover_text(format!(
        "a bake writes a new file: use `bonescope bake FILE --strategy {} --out BAKED.glb`",
        strategy.id()
    ));
}

/// A label in a column `width` wide (the label at its start).
fn slot(ui: &mut Ui, text: RichText, width: f32) -> egui::Response {
    let response = ui.label(text);
    ui.add_space((width - response.rect.width()).max(0.0));
    response
}

/// What a fix leaves of the shear: "removes", "removes (0.04° left)" (within the tolerances), "leaves 38.078°".
fn effect(fix: &Fix) -> String {
    let left = compact(fix.shear_left_deg);
    match (fix.removes, denoised(fix.shear_left_deg) == 0.0) {
        (true, true) => "removes".to_owned(),
        (true, false) => format!("removes ({left}° left)"),
        (false, _) => format!("leaves {left}°"),
    }
}

/// How far a fix moves what is seen, at worst: "skin 69.3 cm", or "bones 1.2 mm" where no mesh shows the bones.
fn distance(fix: &Fix, unit: Option<Unit>) -> String {
    let seen = match fix.cost.measured {
        Measured::Skin => "skin",
        Measured::Bones => "bones",
    };
    format!("{seen} {}", Unit::readable(unit, fix.cost.distance.max))
}

/// A fix's numbers, exact; `when` is the time it moves most, as the timeline shows it.
fn fix_hint(fix: &Fix, unit: Option<Unit>, when: &str) -> String {
    let flagged = if fix.removes { "no longer flagged" } else { "still flagged" };
    let what = match fix.cost.measured {
        Measured::Skin => "the skin",
        Measured::Bones => "the bones' probe points",
    };
    let distance = fix.cost.distance;
    let mut text = format!(
        "{}: {}° of shear left over the clip ({flagged})\nmoves {what} at most {} at {when}, {} % of the rig's size",
        drawable(&fix.label),
        compact(fix.shear_left_deg),
        Unit::readable(unit, distance.max),
        compact(100.0 * fix.cost.fraction)
    );
    if !fix.cleared().is_empty() {
        text.push_str(&format!("\nalso clears {}", fix.cleared().join(", ")));
    }
    if !fix.newly_flagged().is_empty() {
        text.push_str(&format!("\nshears {}, not flagged before", fix.newly_flagged().join(", ")));
    }
    text
}

/// Applies a fix to the document, as `explain` applies it, and shows the clip as it was as the ghost: the modes as
/// they were (declared for a document as opened; declared too where they were mixed) for a mode, the clip without
/// its layers for a uniform scale (the declared modes' ghost would be the fixed pose itself); the plots draw the
/// ghost's curves, dashed over the fixed ones.
fn try_fix(shared: &mut Shared, change: Change) {
    let doc = &mut *shared.doc;
    let ghost = match change {
        Change::Mode { .. } => Ghost::Modes(doc.current_choice(0, ModeScope::All).unwrap_or(ModeChoice::Declared)),
        Change::UniformScale { .. } => Ghost::Unlayered,
        Change::Bake { .. } => return,
    };
    let fixed = change.apply(doc.setup(), &doc.rig.skeleton);
    if fixed.is_ok_and(|setup| doc.set_setup(setup).is_ok()) {
        doc.ghost = Some(ghost);
        shared.settings.plot_ghost = true;
    }
}

fn go_to(shared: &mut Shared, time: f64) {
    *shared.playing = false;
    *shared.time = time;
}

/// The first `shown` of `items`, then the rest under a collapsed "N more".
fn listed<T>(ui: &mut Ui, id: &str, items: &[T], shown: usize, mut row: impl FnMut(&mut Ui, &T)) {
    for item in items.iter().take(shown) {
        row(ui, item);
    }
    if items.len() > shown {
        // Unindented: the rows keep the width their columns were measured for.
        CollapsingHeader::new(format!("{} more", items.len() - shown)).id_salt(id).show_unindented(ui, |ui| {
            for item in &items[shown..] {
                row(ui, item);
            }
        });
    }
}
