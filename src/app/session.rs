//! The session: the open document and its history, the compared file, and the files watched on disk. Loading never
//! replaces the document unless it succeeded; what happens is told through the notifications.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::compared::Compared;
use super::document::Document;
use super::history::History;
use super::notifications::Notifications;
use super::watch::FileWatcher;

/// The files watched for changes on disk.
#[derive(Default)]
struct Watched {
    document: Option<FileWatcher>,
    compared: Option<FileWatcher>,
    /// A file that failed to open, watched so that fixing it opens it.
    broken: Option<(PathBuf, FileWatcher)>,
}

/// How the document was replaced, for the window (which frames a new rig and forgets its selection).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Replaced {
    /// Another file (or the demo): time, selection and camera start anew.
    Opened,
    /// The same file read again; `same_bones` when its bones are the ones it had (the camera stays).
    Reloaded { same_bones: bool },
}

/// The document, its history and the watchers.
pub struct Session {
    pub doc: Document,
    history: History,
    watched: Watched,
    /// For waking the UI from the watchers' threads.
    repaint: Option<egui::Context>,
}

impl Session {
    pub fn new(doc: Document) -> Self {
        let history = History::new(&doc);
        let mut session = Session { doc, history, watched: Watched::default(), repaint: None };
        session.watch_files();
        session
    }

    /// Wakes `ctx` when a watched file changes (the files watched so far included).
    pub fn wake(&mut self, ctx: egui::Context) {
        self.repaint = Some(ctx);
        self.watch_files();
    }

    /// Loads `path`; on failure the document stays, the error is told, and the file is watched, so that fixing it
    /// on disk opens it.
    pub fn open(&mut self, path: &Path, notes: &mut Notifications) -> Option<Replaced> {
        let topic = path.display().to_string();
        match Document::load(path) {
            Ok(doc) => {
                // What was said about the files before (one that failed, a comparison) is of another document.
                notes.clear_errors();
                self.watched.broken = None;
                notes.info_about(&topic, format!("opened {}", path.display()));
                for not_drawn in doc.rig.meshes_not_drawn() {
                    notes.info_about(&topic, not_drawn.to_owned());
                }
                self.replace(doc);
                Some(Replaced::Opened)
            }
            Err(error) => {
                notes.error_about(&topic, error.to_string());
                self.watched.broken = self.watch(path).map(|w| (path.to_owned(), w));
                None
            }
        }
    }

    pub fn open_demo(&mut self) -> Replaced {
        self.replace(Document::demo());
        Replaced::Opened
    }

    /// Another document, with a history of its own.
    fn replace(&mut self, doc: Document) {
        self.history = History::new(&doc);
        self.doc = doc;
        self.watch_files();
    }

    /// Compares the document with the file at `path`, shown as the ghost; on failure the document and any earlier
    /// comparison stay, and the error is told.
    pub fn compare(&mut self, path: &Path, notes: &mut Notifications) {
        let topic = path.display().to_string();
        match Compared::load(path, &self.doc.rig) {
            Ok(compared) => {
                notes.resolved(&topic);
                let unpaired = compared.unpaired();
                let mut message = format!("comparing with {}", path.display());
                if unpaired > 0 {
                    message.push_str(&format!(" ({unpaired} bones have no partner of the same name there)"));
                }
                self.doc.compare_with(compared);
                self.watch_files();
                notes.info_about(&topic, message);
            }
            Err(error) => notes.error_about(&topic, format!("not compared: {error}")),
        }
    }

    pub fn stop_comparing(&mut self) {
        self.doc.stop_comparing();
        self.watch_files();
    }

    /// Reacts to the watched files' changes: the document reloaded, the compared file reloaded, a broken file
    /// opened once fixed.
    pub fn poll(&mut self, notes: &mut Notifications) -> Option<Replaced> {
        let changed = |watcher: &Option<FileWatcher>| watcher.as_ref().is_some_and(FileWatcher::changed);
        if changed(&self.watched.compared) {
            self.reload_compared(notes);
        }
        if let Some((path, watcher)) = &self.watched.broken
            && watcher.changed()
        {
            let path = path.clone();
            return self.open(&path, notes);
        }
        if changed(&self.watched.document) { self.reload(notes) } else { None }
    }

    /// Re-reads the open file after it changed on disk, keeping what is evaluated where it still fits, and the
    /// history.
    fn reload(&mut self, notes: &mut Notifications) -> Option<Replaced> {
        let path = self.doc.path.clone()?;
        let topic = path.display().to_string();
        match crate::import::load(&path) {
            Ok(rig) => {
                let names =
                    |rig: &crate::model::Rig| rig.skeleton.bones().iter().map(|b| b.name.clone()).collect::<Vec<_>>();
                let same_bones = names(&rig) == names(&self.doc.rig);
                let (doc, dropped) = self.doc.reloaded(rig);
                self.doc = doc;
                self.watch_files();
                notes.resolved(&topic);
                match dropped {
                    None => notes.info_about(&topic, format!("reloaded {}", path.display())),
                    Some(error) => {
                        notes.info_about(&topic, format!("reloaded {}; layers dropped: {error}", path.display()))
                    }
                }
                Some(Replaced::Reloaded { same_bones })
            }
            Err(error) => {
                notes.error_about(&topic, format!("not reloaded: {error}"));
                None
            }
        }
    }

    /// Re-reads the compared file after it changed on disk.
    fn reload_compared(&mut self, notes: &mut Notifications) {
        let Some(compared) = self.doc.compared.clone() else { return };
        let topic = compared.path.display().to_string();
        match compared.reloaded(&self.doc.rig) {
            Ok(compared) => {
                self.doc.compared = Some(Arc::new(compared));
                notes.resolved(&topic);
                notes.info_about(&topic, format!("reloaded {topic}"));
            }
            Err(error) => notes.error_about(&topic, format!("not reloaded: {error}")),
        }
    }

    /// Watches the document's file and the compared one.
    fn watch_files(&mut self) {
        self.watched.document = self.doc.path.as_deref().and_then(|path| self.watch(path));
        self.watched.compared = self.doc.compared.as_ref().and_then(|c| self.watch(&c.path));
    }

    /// A watcher of `path` that wakes the UI when it changes.
    fn watch(&self, path: &Path) -> Option<FileWatcher> {
        let ctx = self.repaint.clone();
        FileWatcher::new(path, move |after| {
            if let Some(ctx) = &ctx {
                ctx.request_repaint_after(after);
            }
        })
    }

    /// Takes what the document evaluates now as a step of its history (at the end of a frame in which the user is
    /// not in the middle of a gesture).
    pub fn record(&mut self) {
        self.history.record(&self.doc);
    }

    /// Takes what the document evaluates now in place of the history's current step (a fix tried instead of the
    /// one tried).
    pub fn record_in_place(&mut self) {
        self.history.record_in_place(&self.doc);
    }

    pub fn undo_label(&self) -> Option<&str> {
        self.history.undo_label()
    }

    pub fn redo_label(&self) -> Option<&str> {
        self.history.redo_label()
    }

    /// Every step of the history by its label, and which one the document is in.
    pub fn steps(&self) -> (Vec<&str>, usize) {
        self.history.steps()
    }

    /// Undoes the last step; one that no longer fits the reloaded file is told and stays. The bones it changed back
    /// ([`crate::eval::Setup::changed_bones`]).
    pub fn undo(&mut self, notes: &mut Notifications) -> Vec<usize> {
        self.step(notes, "undo", History::undo)
    }

    /// Redoes the last step undone; the bones it changed.
    pub fn redo(&mut self, notes: &mut Notifications) -> Vec<usize> {
        self.step(notes, "redo", History::redo)
    }

    fn step(
        &mut self,
        notes: &mut Notifications,
        name: &str,
        step: fn(&mut History, &mut Document) -> Result<(), crate::eval::SetupError>,
    ) -> Vec<usize> {
        let before = self.doc.setup().clone();
        match step(&mut self.history, &mut self.doc) {
            Ok(()) => self.doc.setup().changed_bones(&before, &self.doc.rig.skeleton),
            Err(error) => {
                notes.error_about(name, format!("cannot {name}: {error}"));
                Vec::new()
            }
        }
    }
}
