//! The desktop app, in three parts: the **session** (the document, what it evaluates and its history, the compared
//! file, the files watched), the **work** (everything computed off the UI thread, keyed by what it depends on) and
//! the **window** (the panels, the menus, input). This module only ties them together for eframe.
//!
//! Layout: menu and toolbar on top, the outliner left, the inspector right, plots and timeline at the bottom,
//! the viewport in the middle. Loading never replaces the document unless it succeeded; errors become
//! notifications.

mod compared;
mod document;
mod file_browser;
mod frame;
mod history;
mod identity;
mod inspector;
mod job;
mod layers;
mod layout;
mod notifications;
mod outliner;
mod pane;
mod panel;
mod plots;
mod reduce;
mod session;
mod settings;
mod stance;
mod text;
mod ticks;
mod timeline;
mod toolbar;
mod viewport;
mod watch;
mod why;
mod window;
mod work;

use std::path::{Path, PathBuf};

pub use compared::Compared;
pub use document::{Document, Ghost, ModeScope};
pub use file_browser::NativeDialog;
pub use identity::RigId;
pub use notifications::CAPTION_SIDE;
pub use pane::{Layout, Pane};
pub use panel::MAX_PLOTTED;
pub use plots::plot_id;
pub use session::Session;
pub use settings::{RotationFormat, Settings, TimeUnit};
pub use window::{Chrome, Window};
pub use work::{LargestDifferences, Work};

use crate::analysis::ClipAnalysis;
use file_browser::Purpose;
use session::Replaced;
use toolbar::Actions;

/// The bonescope app.
pub struct BonescopeApp {
    pub settings: Settings,
    pub session: Session,
    pub work: Work,
    pub window: Window,
}

impl BonescopeApp {
    /// The app on `doc` with `settings`; the view is framed on the document.
    pub fn new(settings: Settings, doc: Document) -> Self {
        let window = Window::new(&doc);
        BonescopeApp { settings, session: Session::new(doc), work: Work::default(), window }
    }

    /// Starts the app as `bonescope [FILE]` does: settings from eframe's storage, the file or the demo rig.
    pub fn start(cc: &eframe::CreationContext<'_>, file: Option<PathBuf>) -> Self {
        let settings: Settings =
            cc.storage.and_then(|s| eframe::get_value(s, Settings::STORAGE_KEY)).unwrap_or_default();
        let mut app = BonescopeApp::new(settings, Document::demo());
        app.session.wake(cc.egui_ctx.clone());
        app.work.wake(cc.egui_ctx.clone());
        if let Some(path) = file {
            app.open(&path);
        }
        app
    }

    /// Loads `path` (remembered among the recent files whether or not it opens: fixing it on disk opens it).
    pub fn open(&mut self, path: &Path) {
        self.settings.remember(path.to_owned());
        let replaced = self.session.open(path, &mut self.window.notifications);
        self.replaced(replaced);
    }

    /// Compares the document with the file at `path`, shown as the ghost.
    pub fn compare(&mut self, path: &Path) {
        self.session.compare(path, &mut self.window.notifications);
    }

    pub fn open_demo(&mut self) {
        let replaced = self.session.open_demo();
        self.replaced(Some(replaced));
    }

    fn replaced(&mut self, replaced: Option<Replaced>) {
        if let Some(how) = replaced {
            self.window.replaced(how, &self.session.doc);
        }
    }

    /// The whole window for one frame, then what it asked of the session, then the history's step if the user is
    /// not in the middle of a gesture (a slider dragged is one step).
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let replaced = self.session.poll(&mut self.window.notifications);
        self.replaced(replaced);
        let actions = self.window.ui(ui, &mut self.session, &mut self.work, &mut self.settings);
        let in_place = actions.step_in_place;
        self.apply(actions, ui.ctx());
        if in_place {
            self.session.record_in_place();
        } else if !ui.ctx().input(|i| i.pointer.any_down()) {
            self.session.record();
        }
    }

    fn apply(&mut self, actions: Actions, ctx: &egui::Context) {
        for (asked, purpose) in [(actions.open_dialog, Purpose::Open), (actions.compare_dialog, Purpose::Compare)] {
            if asked {
                self.window.choose_file(purpose, ctx, &self.session.doc, &self.settings);
            }
        }
        if actions.undo {
            self.undo();
        }
        if actions.redo {
            self.redo();
        }
        if actions.stop_comparing {
            self.session.stop_comparing();
        }
        if let Some(path) = actions.open {
            self.open(&path);
        }
        if let Some(path) = actions.compare {
            self.compare(&path);
        }
        if actions.open_demo {
            self.open_demo();
        }
        if actions.frame_all {
            self.window.frame_all(&self.session.doc);
        }
    }

    /// Play or pause; playing at the end of a clip that does not loop starts it again.
    pub fn toggle_play(&mut self) {
        self.window.toggle_play(self.settings.looping, self.session.doc.span());
    }

    /// Undoes the last edit of what the document evaluates (Edit → Undo, Ctrl+Z).
    pub fn undo(&mut self) {
        let bones = self.session.undo(&mut self.window.notifications);
        self.window.select_changed(&bones);
    }

    /// Redoes the last edit undone (Edit → Redo, Ctrl+Shift+Z, Ctrl+Y).
    pub fn redo(&mut self) {
        let bones = self.session.redo(&mut self.window.notifications);
        self.window.select_changed(&bones);
    }

    /// Waits for the background work to finish (for tests and headless renders).
    pub fn settle(&mut self) {
        let wanted = self.window.wanted(&self.session.doc, &self.settings);
        self.work.settle(&wanted);
    }

    /// The latest whole-clip analysis, if it matches the current state.
    pub fn analysis(&self) -> Option<&ClipAnalysis> {
        self.work.analysis(&self.window.wanted(&self.session.doc, &self.settings)).map(AsRef::as_ref)
    }

    /// The latest curves of the plotted bones, if they match the current state.
    pub fn curves(&self) -> Option<&ClipAnalysis> {
        self.work.curves(&self.window.wanted(&self.session.doc, &self.settings)).map(AsRef::as_ref)
    }

    /// Each bone's largest difference from the compared file, if computed for the current state.
    pub fn differences(&self) -> Option<&LargestDifferences> {
        self.work.differences(&self.window.wanted(&self.session.doc, &self.settings)).map(AsRef::as_ref)
    }

    /// Where the panel `pane` was drawn in the last frame; `None` when hidden.
    pub fn pane_rect(&self, pane: &Pane) -> Option<egui::Rect> {
        self.window.pane_rect(&self.settings, pane)
    }

    /// Where the messages were drawn in the last frame.
    pub fn notifications_rect(&self) -> Option<egui::Rect> {
        self.window.notifications.rect()
    }

    /// The errors shown, with how many times each was said.
    pub fn errors(&self) -> Vec<(String, usize)> {
        self.window.notifications.errors()
    }

    /// Frames the document now, for a viewport of this aspect ratio (headless renders that then set the camera's
    /// distance themselves).
    pub fn frame_now(&mut self, aspect: f64) {
        self.window.frame_now(&mut self.settings, aspect);
    }
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
