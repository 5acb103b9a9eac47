//! The desktop app: one struct per panel, a shared context they work on, and the eframe glue.
//!
//! Layout: menu and toolbar on top, the outliner left, the inspector right, plots and timeline at the bottom,
//! the viewport in the middle. Loading never replaces the document unless it succeeded; errors become
//! notifications.

mod compare;
mod document;
mod file_browser;
mod inspector;
mod job;
mod layers;
mod layout;
mod notifications;
mod outliner;
mod plots;
mod reduce;
mod settings;
mod text;
mod ticks;
mod timeline;
mod toolbar;
mod viewport;
mod watch;
mod why;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::Receiver;

pub use crate::model::ModeChoice;
pub use compare::Compared;
pub use document::{Document, Ghost, ModeScope, RigId};
pub use file_browser::NativeDialog;
pub use layout::{Layout, Pane};
pub use plots::plot_id;
pub use settings::{RotationFormat, Settings, TimeUnit};

use crate::analysis::{ClipAnalysis, Judged, Tolerances};
use crate::eval::{Pose, SkinningMethod};
use crate::view::DrawnPose;
use compare::{CompareJobs, CompareRequest, ComparedCurves, CurvesRequest, Differences};
use file_browser::{DialogOutcome, FileBrowser};
use job::{AnalysisJob, AnalysisRequest, Key};
use notifications::Notifications;

/// At most this many bones are plotted at once (the most recently selected).
pub const MAX_PLOTTED: usize = 8;

/// The pose at the current time under the document's modes and layers, and the ghost pose.
pub struct CurrentPose {
    pub pose: Pose,
    pub primary: DrawnPose,
    pub ghost: Option<DrawnPose>,
}

impl CurrentPose {
    fn evaluate(doc: &Document, time: f64, skinning: SkinningMethod, tolerances: &Tolerances) -> CurrentPose {
        let rig = &doc.rig;
        let pose = doc.evaluation().pose_at(time);
        let primary = DrawnPose::from_model(rig, pose.model.model.clone(), &pose.morph, skinning, tolerances);
        let ghost = match (&doc.ghost, &doc.compared) {
            (Some(Ghost::Compared), Some(compared)) => {
                Some(compared.ghost(doc.setup().clip, &primary, time, skinning, tolerances))
            }
            _ => doc.ghost_evaluation().map(|evaluation| {
                let ghost = evaluation.pose_at(time);
                DrawnPose::from_model(rig, ghost.model.model, &ghost.morph, skinning, tolerances)
            }),
        };
        CurrentPose { pose, primary, ghost }
    }
}

/// What every panel works on.
pub struct Shared<'a> {
    pub doc: &'a mut Document,
    pub settings: &'a mut Settings,
    pub time: &'a mut f64,
    pub playing: &'a mut bool,
    /// Selected bones; the last one is the inspected one.
    pub selection: &'a mut Vec<usize>,
    pub frame: &'a CurrentPose,
    /// The rig-wide analysis: every bone's summary and stretched samples.
    pub analysis: Option<&'a Arc<ClipAnalysis>>,
    /// The plotted bones' curves (a separate, quick analysis of their chains).
    pub curves: Option<&'a Arc<ClipAnalysis>>,
    /// When the inspected bone (or, with none, any bone) is stretched, per the analysis.
    pub stretched: &'a [(f64, f64)],
    /// `(done, total)` samples while the whole-clip analysis runs.
    pub progress: Option<(usize, usize)>,
    /// Each bone's largest difference from the compared file over the clip, once computed.
    pub differences: Option<&'a Arc<Differences>>,
    /// The compared file's curves of the plotted bones, once computed.
    pub compared_curves: Option<&'a Arc<ComparedCurves>>,
}

impl Shared<'_> {
    /// Selects one bone, or with `extend` adds/removes it from the selection.
    pub fn select(&mut self, bone: usize, extend: bool) {
        if extend {
            if let Some(i) = self.selection.iter().position(|&b| b == bone) {
                self.selection.remove(i);
            } else {
                self.selection.push(bone);
            }
        } else {
            self.selection.clear();
            self.selection.push(bone);
        }
    }

    pub fn inspected(&self) -> Option<usize> {
        self.selection.last().copied()
    }
}

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

/// What a chosen file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Purpose {
    Open,
    Compare,
}

/// The bonescope app.
pub struct BonescopeApp {
    pub settings: Settings,
    pub chrome: Chrome,
    pub doc: Document,
    pub time: f64,
    pub playing: bool,
    pub selection: Vec<usize>,
    job: AnalysisJob,
    curves_job: AnalysisJob,
    compare_jobs: CompareJobs,
    notifications: Notifications,
    watcher: Option<watch::FileWatcher>,
    compared_watcher: Option<watch::FileWatcher>,
    /// A file that failed to open, watched so that fixing it opens it.
    broken: Option<(PathBuf, watch::FileWatcher)>,
    /// The desktop's file dialog while it is open, and what its file is for.
    open_dialog: Option<(Receiver<DialogOutcome>, Purpose)>,
    /// Whether File → Open… may use the desktop's dialog (detected at start; tests set it).
    pub native_dialog: NativeDialog,
    /// bonescope's own file browser, when open, and what its file is for.
    browser: Option<(FileBrowser, Purpose)>,
    /// For waking the UI from background threads (the file watcher).
    repaint: Option<egui::Context>,
    outliner: outliner::Outliner,
    inspector: inspector::Inspector,
    plots: plots::Plots,
    viewport: viewport::Viewport,
    layers: layers::LayersPanel,
    spans: SpanCache,
    clock: timeline::PlayClock,
    /// The window's size in the last frame.
    window_size: egui::Vec2,
}

impl BonescopeApp {
    /// The app on `doc` with `settings`; the view is framed on the document.
    pub fn new(settings: Settings, doc: Document) -> Self {
        let mut app = BonescopeApp {
            settings,
            chrome: Chrome::Window,
            doc,
            time: 0.0,
            playing: false,
            selection: Vec::new(),
            job: AnalysisJob::default(),
            curves_job: AnalysisJob::default(),
            compare_jobs: CompareJobs::default(),
            notifications: Notifications::default(),
            watcher: None,
            compared_watcher: None,
            broken: None,
            open_dialog: None,
            native_dialog: NativeDialog::detect(),
            browser: None,
            repaint: None,
            outliner: outliner::Outliner::default(),
            inspector: inspector::Inspector::default(),
            plots: plots::Plots::default(),
            viewport: viewport::Viewport::default(),
            layers: layers::LayersPanel::default(),
            spans: SpanCache::default(),
            clock: timeline::PlayClock::default(),
            window_size: egui::Vec2::ZERO,
        };
        app.document_replaced(true);
        app
    }

    /// Starts the app as `bonescope [FILE]` does: settings from eframe's storage, the file or the demo rig.
    pub fn start(cc: &eframe::CreationContext<'_>, file: Option<PathBuf>) -> Self {
        let settings: Settings =
            cc.storage.and_then(|s| eframe::get_value(s, Settings::STORAGE_KEY)).unwrap_or_default();
        let mut app = BonescopeApp::new(settings, Document::demo());
        app.repaint = Some(cc.egui_ctx.clone());
        if let Some(path) = file {
            app.open(&path);
        }
        app
    }

    /// Loads `path`; on failure the current document stays, the error becomes a notification, and the file is
    /// listed in the recent files and watched, so that fixing it on disk opens it.
    pub fn open(&mut self, path: &Path) {
        let topic = path.display().to_string();
        self.settings.remember(path.to_owned());
        match Document::load(path) {
            Ok(doc) => {
                self.notifications.resolved(&topic);
                self.broken = None;
                self.doc = doc;
                self.selection.clear();
                self.time = 0.0;
                self.document_replaced(true);
                self.notifications.info_about(&topic, format!("opened {}", path.display()));
            }
            Err(error) => {
                self.notifications.error_about(&topic, error.to_string());
                self.broken = self.watch(path).map(|w| (path.to_owned(), w));
            }
        }
    }

    /// Compares the document with the file at `path`, shown as the ghost; on failure the document and any earlier
    /// comparison stay, and the error becomes a notification.
    pub fn compare(&mut self, path: &Path) {
        let topic = path.display().to_string();
        match Compared::load(path, &self.doc.rig) {
            Ok(compared) => {
                self.notifications.resolved(&topic);
                let unpaired = compared.unpaired();
                let mut message = format!("comparing with {}", path.display());
                if unpaired > 0 {
                    message.push_str(&format!(" ({unpaired} bones have no partner of the same name there)"));
                }
                self.doc.compare_with(compared);
                self.compared_replaced();
                self.notifications.info_about(&topic, message);
            }
            Err(error) => self.notifications.error_about(&topic, format!("not compared: {error}")),
        }
    }

    /// Re-reads the compared file after it changed on disk.
    fn reload_compared(&mut self) {
        let Some(compared) = self.doc.compared.clone() else { return };
        let path = compared.path.clone();
        match compared.reloaded(&self.doc.rig) {
            Ok(compared) => {
                self.doc.compared = Some(Arc::new(compared));
                self.compared_replaced();
                self.notifications.resolved(&path.display().to_string());
                self.notifications.info_about(&path.display().to_string(), format!("reloaded {}", path.display()));
            }
            Err(error) => self.notifications.error_about(&path.display().to_string(), format!("not reloaded: {error}")),
        }
    }

    fn compared_replaced(&mut self) {
        self.compared_watcher = self.doc.compared.as_ref().and_then(|c| self.watch(&c.path));
    }

    /// A watcher of `path` that wakes the UI when it changes.
    fn watch(&self, path: &Path) -> Option<watch::FileWatcher> {
        let ctx = self.repaint.clone();
        watch::FileWatcher::new(path, move |after| {
            if let Some(ctx) = &ctx {
                ctx.request_repaint_after(after);
            }
        })
    }

    pub fn open_demo(&mut self) {
        self.doc = Document::demo();
        self.selection.clear();
        self.document_replaced(true);
    }

    /// Re-reads the open file after it changed on disk, keeping time, selection, camera and modes.
    fn reload(&mut self) {
        let Some(path) = self.doc.path.clone() else { return };
        match crate::import::load(&path) {
            Ok(rig) => {
                // A file rewritten with another rig is framed anew; the same rig keeps the camera.
                let names =
                    |rig: &crate::model::Rig| rig.skeleton.bones().iter().map(|b| b.name.clone()).collect::<Vec<_>>();
                let same_rig = names(&rig) == names(&self.doc.rig);
                let topic = path.display().to_string();
                let (doc, dropped) = self.doc.reloaded(rig);
                self.doc = doc;
                let bones = self.doc.rig.skeleton.len();
                self.selection.retain(|&b| b < bones);
                self.document_replaced(!same_rig);
                self.notifications.resolved(&path.display().to_string());
                match dropped {
                    None => self.notifications.info_about(&topic, format!("reloaded {}", path.display())),
                    Some(error) => self
                        .notifications
                        .info_about(&topic, format!("reloaded {}; layers dropped: {error}", path.display())),
                }
            }
            Err(error) => self.notifications.error_about(&path.display().to_string(), format!("not reloaded: {error}")),
        }
    }

    fn document_replaced(&mut self, frame_camera: bool) {
        self.watcher = self.doc.path.as_deref().and_then(|path| self.watch(path));
        if self.doc.compared.is_none() {
            self.compared_watcher = None;
        }
        if frame_camera {
            self.viewport.frame_all(&self.doc);
        }
        self.time = self.time.clamp(0.0, self.doc.duration());
    }

    /// The rig-wide analysis the UI wants now: every bone judged over the clip, no curves. It does not change with
    /// the selection, so selecting a bone never waits for it.
    fn job_key(&self) -> Key<AnalysisRequest> {
        let request = AnalysisRequest {
            ghost: None,
            plotted: Vec::new(),
            rate: self.doc.analysis_rate(),
            tolerances: self.settings.tolerances,
            judged: Judged::Every,
        };
        Key::of(&self.doc, request)
    }

    /// The curves the plots want now: the plotted bones (and the ghost's), only their chains evaluated; `None`
    /// with nothing selected.
    fn curves_key(&self) -> Option<Key<AnalysisRequest>> {
        let plotted = self.plotted();
        let mut key = self.job_key();
        key.request =
            AnalysisRequest { plotted, ghost: self.doc.ghost_setup(), judged: Judged::CurveChains, ..key.request };
        (!key.request.plotted.is_empty()).then_some(key)
    }

    /// What the comparison with the compared file depends on, when there is one.
    fn compare_key(&self) -> Option<Key<CompareRequest>> {
        let compared = self.doc.compared.as_ref()?;
        Some(CompareRequest::of(&self.doc, compared, self.doc.analysis_rate()))
    }

    /// What the compared file's curves depend on: the compared file as evaluated, the plotted bones, and the times
    /// of the document's own curves (the dashed curves share their axis).
    fn compared_curves_key(&self) -> Option<Key<CurvesRequest>> {
        let times = self.curves()?.times.clone();
        let compare = self.compare_key()?;
        let request = CurvesRequest { plotted: self.plotted(), times };
        Some(Key { rig: compare.request.compared, setup: compare.request.setup, request })
    }

    /// Starts the analyses the current state wants (each only when its key changed).
    fn request_analyses(&mut self, ctx: &egui::Context) {
        let rig = &self.doc.rig;
        let key = self.job_key();
        let waker = ctx.clone();
        let work = || job::analysis(key.clone(), rig.clone());
        self.job.update(key.clone(), work, move || waker.request_repaint());
        if let Some(key) = self.curves_key() {
            let waker = ctx.clone();
            let work = || job::analysis(key.clone(), rig.clone());
            self.curves_job.update(key.clone(), work, move || waker.request_repaint());
        }
        let Some(compared) = self.doc.compared.clone() else { return };
        if let Some(key) = self.compare_key() {
            let work = || compare::differences(key.clone(), rig.clone(), compared.clone());
            let waker = ctx.clone();
            self.compare_jobs.differences.update(key.clone(), work, move || waker.request_repaint());
        }
        if let Some(key) = self.compared_curves_key() {
            let work = || compare::curves(key.clone(), compared);
            let waker = ctx.clone();
            self.compare_jobs.curves.update(key.clone(), work, move || waker.request_repaint());
        }
    }

    /// The bones whose curves are plotted: the most recently selected ones.
    pub fn plotted(&self) -> Vec<usize> {
        let skip = self.selection.len().saturating_sub(MAX_PLOTTED);
        let mut bones: Vec<usize> = self.selection[skip..].to_vec();
        bones.sort_unstable();
        bones
    }

    /// Frames the document now, for a viewport of this aspect ratio, instead of at the next frame (headless
    /// renders that then set the camera's distance themselves).
    pub fn frame_now(&mut self, aspect: f64) {
        self.viewport.frame_now(&mut self.settings.camera, aspect);
    }

    /// Waits for the background analysis to finish (for tests and headless renders).
    pub fn settle(&mut self, ctx: &egui::Context) {
        self.request_analyses(ctx);
        self.job.wait();
        self.curves_job.wait();
        self.compare_jobs.differences.wait();
        // The compared curves wait for the document's.
        self.request_analyses(ctx);
        self.compare_jobs.curves.wait();
        self.layers.settle();
        self.inspector.settle();
    }

    /// Each bone's largest difference from the compared file, if computed for the current state.
    pub fn differences(&self) -> Option<&Differences> {
        self.compare_jobs.differences.for_key(&self.compare_key()?).map(Arc::as_ref)
    }

    /// The latest whole-clip analysis, if it matches the current state.
    pub fn analysis(&self) -> Option<&ClipAnalysis> {
        self.job.for_key(&self.job_key()).map(Arc::as_ref)
    }

    /// The latest curves of the plotted bones, if they match the current state.
    pub fn curves(&self) -> Option<&ClipAnalysis> {
        self.curves_job.for_key(&self.curves_key()?).map(Arc::as_ref)
    }

    /// Where `pane` was drawn in the last frame; `None` when hidden.
    pub fn pane_rect(&self, pane: Pane) -> Option<egui::Rect> {
        let tiles = &self.settings.layout.as_ref()?.tiles;
        let tile = tiles.find_pane(&pane)?;
        tiles.is_visible(tile).then(|| tiles.rect(tile)).flatten()
    }

    /// Where the messages were drawn in the last frame.
    pub fn notifications_rect(&self) -> Option<egui::Rect> {
        self.notifications.rect()
    }

    /// The errors shown, with how many times each was said.
    pub fn errors(&self) -> Vec<(String, usize)> {
        self.notifications.errors()
    }

    /// The whole window.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        ctx.set_theme(if self.settings.dark { egui::Theme::Dark } else { egui::Theme::Light });
        // After a resize the panels settle their sizes over a frame or two: draw those at once, not at the next
        // input (the window would show a strip of nothing meanwhile).
        let size = ctx.content_rect().size();
        if std::mem::replace(&mut self.window_size, size) != size {
            ctx.request_repaint();
        }
        self.poll_background(&ctx);
        self.handle_input(&ctx);
        self.advance_playback(&ctx);
        let frame =
            CurrentPose::evaluate(&self.doc, self.time, self.settings.scene.skinning, &self.settings.tolerances);
        let latest = self.job.latest().map(|(_, a)| a.clone());
        let curves = self.curves_job.latest().map(|(_, a)| a.clone());
        let comparing = self.doc.compared.is_some();
        let differences = self.compare_jobs.differences.latest().filter(|_| comparing).map(|(_, d)| d.clone());
        let compared_curves = self.compare_jobs.curves.latest().filter(|_| comparing).map(|(_, c)| c.clone());
        let progress = self.job.progress();
        let stretched = self.spans.get(latest.as_ref(), self.selection.last().copied());
        let mut actions = toolbar::Actions::default();
        {
            let mut shared = Shared {
                doc: &mut self.doc,
                settings: &mut self.settings,
                time: &mut self.time,
                playing: &mut self.playing,
                selection: &mut self.selection,
                frame: &frame,
                analysis: latest.as_ref(),
                curves: curves.as_ref(),
                stretched,
                progress,
                differences: differences.as_ref(),
                compared_curves: compared_curves.as_ref(),
            };
            if self.chrome == Chrome::ViewportOnly {
                egui::CentralPanel::default()
                    .frame(egui::Frame::NONE)
                    .show(ui, |ui| self.viewport.canvas(ui, &mut shared, viewport::CanvasFill::Left));
            } else {
                egui::Panel::top("menu").show(ui, |ui| toolbar::ui(ui, &mut shared, &mut actions));
                egui::Panel::bottom("timeline").resizable(false).show(ui, |ui| timeline::ui(ui, &mut shared));
                let width = ui.ctx().content_rect().width();
                // The panels' background under the tiles (which paint none of their own).
                let fill = egui::Frame::NONE.fill(ui.visuals().panel_fill);
                egui::CentralPanel::default().frame(fill).show(ui, |ui| {
                    // The arrangement lives in the settings (it persists); the panes borrow them through `shared`.
                    let mut layout = layout::take_layout(shared.settings, width);
                    let mut panes = layout::Panes {
                        shared: &mut shared,
                        outliner: &mut self.outliner,
                        inspector: &mut self.inspector,
                        plots: &mut self.plots,
                        viewport: &mut self.viewport,
                        layers: &mut self.layers,
                        style: ui.style().clone(),
                    };
                    layout.ui(&mut panes, ui);
                    shared.settings.layout = Some(layout);
                });
            }
        }
        self.notifications.ui(&ctx, self.viewport.rect().unwrap_or_else(|| ctx.content_rect()));
        if let Some((browser, purpose)) = &mut self.browser {
            let mut open = true;
            let chosen = browser.ui(&ctx, &mut open).map(|path| (path, *purpose));
            if !open {
                self.browser = None;
            }
            if let Some((path, purpose)) = chosen {
                self.chosen(&path, purpose);
            }
        }
        self.apply(actions, &ctx);
    }

    fn apply(&mut self, actions: toolbar::Actions, ctx: &egui::Context) {
        if actions.open_dialog {
            self.choose_file(Purpose::Open, ctx);
        }
        if actions.compare_dialog {
            self.choose_file(Purpose::Compare, ctx);
        }
        if actions.stop_comparing {
            self.doc.stop_comparing();
            self.compared_watcher = None;
        }
        if let Some(path) = actions.open {
            self.open(&path);
        }
        if actions.open_demo {
            self.open_demo();
        }
        if actions.frame_all {
            self.viewport.frame_all(&self.doc);
        }
        if actions.clip_changed {
            self.time = 0.0;
        }
    }

    /// Asks for a file (the desktop's dialog where there is one, else bonescope's own browser) for `purpose`.
    fn choose_file(&mut self, purpose: Purpose, ctx: &egui::Context) {
        match self.native_dialog {
            NativeDialog::Available => self.open_dialog = Some((spawn_open_dialog(ctx.clone()), purpose)),
            NativeDialog::Unavailable => self.open_browser(purpose),
        }
    }

    /// Does with a chosen file what it was chosen for.
    fn chosen(&mut self, path: &Path, purpose: Purpose) {
        match purpose {
            Purpose::Open => self.open(path),
            Purpose::Compare => self.compare(path),
        }
    }

    /// Shows bonescope's own file browser (the desktop has no dialog), in the open file's folder or the most
    /// recent one's.
    fn open_browser(&mut self, purpose: Purpose) {
        self.notifications.info("no desktop file dialog here (no XDG portal): using bonescope's own".to_owned());
        let recent = self.doc.path.as_ref().or(self.settings.recent.first());
        let folder = recent.and_then(|p| p.parent()).filter(|p| p.is_dir()).map(Path::to_owned);
        let folder = folder.or_else(|| std::env::current_dir().ok()).unwrap_or_else(|| PathBuf::from("."));
        let title = match purpose {
            Purpose::Open => "Open a file",
            Purpose::Compare => "Compare with a file",
        };
        self.browser = Some((FileBrowser::new(title, &folder), purpose));
    }

    fn poll_background(&mut self, ctx: &egui::Context) {
        if let Some((dialog, purpose)) = &self.open_dialog
            && let Ok(outcome) = dialog.try_recv()
        {
            let purpose = *purpose;
            self.open_dialog = None;
            match outcome {
                DialogOutcome::Chosen(path) => self.chosen(&path, purpose),
                DialogOutcome::Cancelled => {}
                DialogOutcome::Failed => {
                    self.native_dialog = NativeDialog::Unavailable;
                    self.open_browser(purpose);
                }
            }
        }
        if self.watcher.as_ref().is_some_and(watch::FileWatcher::changed) {
            self.reload();
        }
        if self.compared_watcher.as_ref().is_some_and(watch::FileWatcher::changed) {
            self.reload_compared();
        }
        if let Some((path, watcher)) = &self.broken
            && watcher.changed()
        {
            let path = path.clone();
            self.open(&path);
        }
        // The viewport alone shows nothing of the whole-clip analysis.
        if self.chrome == Chrome::ViewportOnly {
            return;
        }
        self.request_analyses(ctx);
        let compare_running =
            self.compare_jobs.differences.progress().is_some() || self.compare_jobs.curves.progress().is_some();
        if self.job.progress().is_some() || self.curves_job.progress().is_some() || compare_running {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_owned()).collect());
        if let Some(path) = dropped.first() {
            self.open(path);
        }
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let pressed = |key| ctx.input(|i| i.key_pressed(key));
        let duration = self.doc.duration();
        if pressed(egui::Key::Space) {
            self.toggle_play();
        }
        for (key, forward) in [(egui::Key::ArrowLeft, false), (egui::Key::ArrowRight, true)] {
            // A held key repeats faster than slow frames come: every repeat is a frame.
            for _ in 0..ctx.input(|i| i.num_presses(key)) {
                self.playing = false;
                self.time = timeline::step_frame(self.time, self.doc.frame_rate(), forward, duration);
            }
        }
        for (key, to) in [(egui::Key::Home, 0.0), (egui::Key::End, duration)] {
            if pressed(key) {
                self.playing = false;
                self.time = to;
            }
        }
    }

    /// Play or pause; playing at the end of a clip that does not loop starts it again.
    pub fn toggle_play(&mut self) {
        timeline::toggle_play(&mut self.playing, &mut self.time, self.settings.looping, self.doc.duration());
    }

    fn advance_playback(&mut self, ctx: &egui::Context) {
        let now = ctx.input(|i| i.time);
        let dt = self.clock.tick(now, self.playing) * self.settings.speed;
        if !self.playing {
            return;
        }
        let duration = self.doc.duration();
        self.time += dt;
        if self.time > duration {
            if self.settings.looping && duration > 0.0 {
                self.time %= duration;
            } else {
                self.time = duration;
                self.playing = false;
            }
        }
        ctx.request_repaint();
    }
}

/// Runs the native file dialog on its own thread so the UI keeps drawing.
fn spawn_open_dialog(ctx: egui::Context) -> Receiver<DialogOutcome> {
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = sender.send(file_browser::run_native_dialog());
        ctx.request_repaint();
    });
    receiver
}

impl eframe::App for BonescopeApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        BonescopeApp::ui(self, ui);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, Settings::STORAGE_KEY, &self.settings);
    }
}

/// Opens the desktop window: `bonescope [FILE]`.
pub fn run(file: Option<PathBuf>) -> eframe::Result {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default().with_inner_size([1400.0, 900.0]).with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native("bonescope", options, Box::new(|cc| Ok(Box::new(BonescopeApp::start(cc, file)))))
}
