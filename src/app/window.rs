//! The window: the panels in their tiles, the menu bar and toolbar, the timeline, the messages and the file
//! dialogs; time, play and selection; the keys. It draws the session's document with what the work computed, and
//! returns what the user asked that changes the session ([`Actions`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::document::Document;
use super::file_browser::{Dialogs, Purpose};
use super::frame::CurrentPose;
use super::layout::{Panes, take_layout};
use super::notifications::Notifications;
use super::pane::Pane;
use super::panel::{Panel, Shared, plotted};
use super::session::{Replaced, Session};
use super::settings::Settings;
use super::timeline::{self, PlayClock};
use super::toolbar::{self, Actions, Menus};
use super::viewport::{CanvasFill, Viewport};
use super::work::{Wanted, Work};
use super::{inspector, layers, outliner, plots, why};
use crate::analysis::ClipAnalysis;
use crate::model::Span;

/// What the window shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Chrome {
    /// Menus, panels, plots, timeline and the viewport.
    #[default]
    Window,
    /// The viewport's picture alone, edge to edge, on a transparent background (headless renders of the viewport).
    ViewportOnly,
}

/// The stretched spans of the inspected bone (or of any bone), kept until the analysis or the bone changes: walking
/// a long clip's flags every frame would cost more than drawing them.
#[derive(Default)]
struct SpanCache {
    key: Option<(Arc<ClipAnalysis>, Option<usize>)>,
    spans: Vec<(f64, f64)>,
}

impl SpanCache {
    fn get(&mut self, analysis: Option<&Arc<ClipAnalysis>>, bone: Option<usize>) -> &[(f64, f64)] {
        let Some(analysis) = analysis else { return &[] };
        if self.key.as_ref().is_none_or(|(a, b)| !Arc::ptr_eq(a, analysis) || *b != bone) {
            self.spans = analysis.stretched_spans(bone);
            self.key = Some((analysis.clone(), bone));
        }
        &self.spans
    }
}

/// The window's state.
pub struct Window {
    pub chrome: Chrome,
    /// On the clip's own clock, within the timeline's span.
    pub time: f64,
    pub playing: bool,
    /// The timeline's span in the last frame, to notice it change.
    span: Span,
    /// Selected bones; the last one is the inspected one.
    pub selection: Vec<usize>,
    /// Whether the first view of a file opened is still to come from its whole-clip analysis.
    /// Headless renders, which say what to show, turn it off.
    pub opening: bool,
    viewport: Viewport,
    panels: Vec<Box<dyn Panel>>,
    spans: SpanCache,
    clock: PlayClock,
    /// The window's size in the last frame.
    size: egui::Vec2,
    pub notifications: Notifications,
    pub dialogs: Dialogs,
}

impl Window {
    /// A window on `doc`, framed on it.
    pub fn new(doc: &Document) -> Self {
        let mut window = Window {
            chrome: Chrome::Window,
            time: 0.0,
            playing: false,
            span: Span::default(),
            selection: Vec::new(),
            opening: false,
            viewport: Viewport::default(),
            panels: panels(),
            spans: SpanCache::default(),
            clock: PlayClock::default(),
            size: egui::Vec2::ZERO,
            notifications: Notifications::default(),
            dialogs: Dialogs::default(),
        };
        window.replaced(Replaced::Opened, doc);
        window
    }

    /// Follows a document replaced in the session: another file starts at its clip's start with nothing selected
    /// and is framed; a reloaded one keeps time and selection, and the camera unless its bones changed.
    pub fn replaced(&mut self, how: Replaced, doc: &Document) {
        match how {
            Replaced::Opened => {
                self.opening = true;
                self.selection.clear();
                self.span = doc.span();
                self.time = self.span.start;
                self.viewport.frame_all(doc);
            }
            Replaced::Reloaded { same_bones } => {
                let bones = doc.rig.skeleton.len();
                self.selection.retain(|&b| b < bones);
                if !same_bones {
                    self.viewport.frame_all(doc);
                }
            }
        }
    }

    /// The first view of a file opened, once its whole-clip analysis is there: where a bone shears, the worst one
    /// selected (its shear plotted, the Why? section open) at its worst time; where none does, a line that says so,
    /// the clip staying at its start. A bone or a time the user chose while the analysis ran stands.
    fn open_on_the_problem(&mut self, ctx: &egui::Context, doc: &Document, work: &Work, settings: &Settings) {
        if !self.opening {
            return;
        }
        let Some(analysis) = work.analysis(&self.wanted(doc, settings)) else { return };
        self.opening = false;
        if !self.selection.is_empty() || self.time != self.span.start || self.playing {
            return;
        }
        match analysis.scan.stretched_worst_first().first() {
            Some(worst) => {
                self.selection = vec![worst.index];
                self.time = worst.worst_shear_time;
                why::open(ctx);
                ctx.request_repaint();
            }
            None => {
                let clip = doc.clip().map_or_else(|| "the rest pose".to_owned(), |c| format!("`{}`", c.label()));
                let bones = analysis.scan.bones.len();
                self.notifications.info_about(&doc.title(), format!("no bone shears in {clip}: 0 of {bones} bones"));
            }
        }
    }

    /// Selects the topmost of the bones an undo or redo changed (`bones`, parents first), so that the step shows;
    /// a step of no bone in particular leaves the selection.
    pub fn select_changed(&mut self, bones: &[usize]) {
        if let Some(&top) = bones.first() {
            self.selection = vec![top];
        }
    }

    /// Keeps the time within the timeline when the timeline changes: another clip, an undo, a crossfade moved.
    fn follow_span(&mut self, span: Span) {
        if std::mem::replace(&mut self.span, span) != span {
            self.time = span.clamp(self.time);
        }
    }

    /// The viewport and the tiled panels.
    fn all_panels(&self) -> Vec<&dyn Panel> {
        std::iter::once(&self.viewport as &dyn Panel).chain(self.panels.iter().map(|p| p.as_ref())).collect()
    }

    /// What the work is asked this frame: the document's analysis, and the plotted bones' curves where a panel
    /// shown plots them.
    pub fn wanted<'a>(&self, doc: &'a Document, settings: &Settings) -> Wanted<'a> {
        let plots = self.all_panels().iter().any(|p| p.plots_curves() && settings.shows(&p.pane(), p.visibility()));
        let plotted = if plots { self.plotted() } else { Vec::new() };
        Wanted { doc, tolerances: settings.tolerances, plotted }
    }

    /// The bones whose curves are plotted.
    pub fn plotted(&self) -> Vec<usize> {
        plotted(&self.selection)
    }

    /// The whole window for a frame; what the user asked that changes the session.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        session: &mut Session,
        work: &mut Work,
        settings: &mut Settings,
    ) -> Actions {
        let ctx = ui.ctx().clone();
        ctx.set_theme(if settings.dark { egui::Theme::Dark } else { egui::Theme::Light });
        // After a resize the panels settle their sizes over a frame or two: draw those at once, not at the next
        // input (the window would show a strip of nothing meanwhile).
        let size = ctx.content_rect().size();
        if std::mem::replace(&mut self.size, size) != size {
            ctx.request_repaint();
        }
        self.follow_span(session.doc.span());
        let mut actions = self.input(&ctx, &session.doc, settings.looping);
        self.advance_playback(&ctx, settings, &session.doc);
        // The viewport alone shows nothing of the whole-clip analysis.
        if self.chrome == Chrome::Window {
            work.analyse(&self.wanted(&session.doc, settings));
            if work.analysing() {
                ctx.request_repaint_after(std::time::Duration::from_millis(100));
            }
        }
        let panes = self.all_panels().iter().map(|p| (p.pane(), p.visibility())).collect();
        let [undo, redo] = [session.undo_label(), session.redo_label()].map(|label| label.map(str::to_owned));
        let (steps, current) = session.steps();
        let history = steps.into_iter().map(str::to_owned).collect();
        let menus = Menus { undo, redo, history, current, panels: panes };
        let doc = &mut session.doc;
        let frame = CurrentPose::evaluate(doc, self.time, settings.scene.skinning, &settings.tolerances);
        let results = work.results(doc);
        let stretched = self.spans.get(results.analysis.as_ref(), self.selection.last().copied());
        let (mut undo_asked, mut step_in_place) = (false, false);
        let mut shared = Shared {
            doc,
            settings,
            time: &mut self.time,
            playing: &mut self.playing,
            selection: &mut self.selection,
            frame: &frame,
            results: &results,
            stretched,
            work,
            undo_asked: &mut undo_asked,
            step_in_place: &mut step_in_place,
        };
        if self.chrome == Chrome::ViewportOnly {
            egui::CentralPanel::default()
                .frame(egui::Frame::NONE)
                .show(ui, |ui| self.viewport.canvas(ui, &mut shared, CanvasFill::Left));
        } else {
            egui::Panel::top("menu").show(ui, |ui| toolbar::ui(ui, &mut shared, &menus, &mut actions));
            egui::Panel::bottom("timeline").resizable(false).show(ui, |ui| timeline::ui(ui, &mut shared));
            let width = ui.ctx().content_rect().width();
            // The panels' background under the tiles (which paint none of their own).
            let fill = egui::Frame::NONE.fill(ui.visuals().panel_fill);
            egui::CentralPanel::default().frame(fill).show(ui, |ui| {
                // The arrangement lives in the settings (it persists); the panes borrow them through `shared`.
                let all = std::iter::once(&self.viewport as &dyn Panel).chain(self.panels.iter().map(|p| p.as_ref()));
                let mut layout = take_layout(shared.settings, width, &all.collect::<Vec<_>>());
                let style = ui.style().clone();
                // The gaps between the tiles are their resize handles, edge to edge.
                ui.style_mut().interaction.resize_grab_radius_side = super::layout::GRAB_RADIUS;
                let mut panes =
                    Panes { shared: &mut shared, viewport: &mut self.viewport, panels: &mut self.panels, style };
                layout.ui(&mut panes, ui);
                shared.settings.layout = Some(layout);
            });
        }
        actions.undo |= undo_asked;
        actions.step_in_place = step_in_place;
        // After the panels: a bone clicked in this very frame stands.
        if self.chrome == Chrome::Window {
            self.open_on_the_problem(&ctx, &session.doc, work, settings);
        }
        self.notifications.ui(&ctx, self.viewport.messages_rect().unwrap_or_else(|| ctx.content_rect()));
        let folder = browsing_folder(&session.doc, settings);
        if let Some((path, purpose)) = self.dialogs.ui(&ctx, &folder, &mut self.notifications) {
            match purpose {
                Purpose::Open => actions.open = Some(path),
                Purpose::Compare => actions.compare = Some(path),
            }
        }
        actions
    }

    /// Play or pause; playing at the end of a clip that does not loop starts it again from its start.
    pub fn toggle_play(&mut self, looping: bool, span: Span) {
        timeline::toggle_play(&mut self.playing, &mut self.time, looping, span);
    }

    /// Where the next frame is framed: the document's whole motion.
    pub fn frame_all(&mut self, doc: &Document) {
        self.viewport.frame_all(doc);
    }

    /// Frames the document now, for a viewport of this aspect ratio, instead of at the next frame (headless
    /// renders that then set the camera's distance themselves).
    pub fn frame_now(&mut self, settings: &mut Settings, aspect: f64) {
        self.viewport.frame_now(&mut settings.camera, aspect);
    }

    /// Asks for a file for `purpose`.
    pub fn choose_file(&mut self, purpose: Purpose, ctx: &egui::Context, doc: &Document, settings: &Settings) {
        let folder = browsing_folder(doc, settings);
        self.dialogs.choose(purpose, ctx, &folder, &mut self.notifications);
    }

    /// The keys (and a dropped file): play, step, the ends of the clip, undo and redo.
    fn input(&mut self, ctx: &egui::Context, doc: &Document, looping: bool) -> Actions {
        let mut actions = Actions::default();
        let dropped: Vec<PathBuf> = ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_owned()).collect());
        actions.open = dropped.into_iter().next();
        if ctx.egui_wants_keyboard_input() {
            return actions;
        }
        toolbar::history_keys(ctx, &mut actions);
        let pressed = |key| ctx.input(|i| i.key_pressed(key));
        let span = doc.span();
        if pressed(egui::Key::Space) {
            self.toggle_play(looping, span);
        }
        for (key, forward) in [(egui::Key::ArrowLeft, false), (egui::Key::ArrowRight, true)] {
            // A held key repeats faster than slow frames come: every repeat is a frame.
            for _ in 0..ctx.input(|i| i.num_presses(key)) {
                self.playing = false;
                self.time = timeline::step_frame(self.time, doc.frame_rate(), forward, span);
            }
        }
        for (key, to) in [(egui::Key::Home, span.start), (egui::Key::End, span.end)] {
            if pressed(key) {
                self.playing = false;
                self.time = to;
            }
        }
        actions
    }

    fn advance_playback(&mut self, ctx: &egui::Context, settings: &Settings, doc: &Document) {
        let now = ctx.input(|i| i.time);
        let dt = self.clock.tick(now, self.playing) * settings.speed;
        if !self.playing {
            return;
        }
        (self.time, self.playing) = timeline::played(self.time, dt, doc.span(), settings.looping);
        ctx.request_repaint();
    }

    /// Where `pane` was drawn in the last frame; `None` when hidden.
    pub fn pane_rect(&self, settings: &Settings, pane: &Pane) -> Option<egui::Rect> {
        let tiles = &settings.layout.as_ref()?.tiles;
        let tile = tiles.find_pane(pane)?;
        tiles.is_visible(tile).then(|| tiles.rect(tile)).flatten()
    }
}

/// The folder bonescope's own file browser opens in: the open file's, or the most recent one's.
fn browsing_folder(doc: &Document, settings: &Settings) -> PathBuf {
    let recent = doc.path.as_ref().or(settings.recent.first());
    let folder = recent.and_then(|p| p.parent()).filter(|p| p.is_dir()).map(Path::to_owned);
    folder.or_else(|| std::env::current_dir().ok()).unwrap_or_else(|| PathBuf::from("."))
}

/// Every panel of the tile layout but the viewport (the window holds it itself: a headless render draws it alone),
/// in the order the first arrangement lists them.
pub(super) fn panels() -> Vec<Box<dyn Panel>> {
    vec![
        Box::new(outliner::Outliner::default()),
        Box::new(inspector::Inspector::default()),
        Box::new(layers::LayersPanel::default()),
        Box::new(plots::Plots::default()),
    ]
}
