//! File → Open… that always does something: the desktop's own dialog where there is one, else bonescope's.
//!
//! On Linux the native dialog goes through the XDG desktop portal over D-Bus; on a workstation without a full
//! desktop (or in CI) there is none, and the dialog silently returns nothing. So the app asks for the native dialog
//! only where a session bus exists, treats an answer faster than a person can cancel as a failure, and falls back
//! to this browser: a path field (type or paste a path, Enter opens it), the folder's sub-folders and animation
//! files to click, and Up.

use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use super::notifications::Notifications;
use crate::import::Format;

/// A native dialog that answers sooner than this without a file did not really open.
const TOO_FAST: Duration = Duration::from_millis(300);

/// Whether a native file dialog can be shown here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NativeDialog {
    Available,
    Unavailable,
}

impl NativeDialog {
    /// What this machine offers: on Linux and the BSDs a D-Bus session is needed for the portal.
    pub fn detect() -> Self {
        let needs_portal = cfg!(all(unix, not(target_os = "macos")));
        if needs_portal && std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_none() {
            NativeDialog::Unavailable
        } else {
            NativeDialog::Available
        }
    }
}

/// How a native dialog ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DialogOutcome {
    Chosen(PathBuf),
    Cancelled,
    /// It returned at once with nothing: no portal answered.
    Failed,
}

impl DialogOutcome {
    /// The outcome of a dialog that returned `choice` after `elapsed`.
    pub fn of(choice: Option<PathBuf>, elapsed: Duration) -> Self {
        match choice {
            Some(path) => DialogOutcome::Chosen(path),
            None if elapsed < TOO_FAST => DialogOutcome::Failed,
            None => DialogOutcome::Cancelled,
        }
    }
}

/// Runs the native dialog and times it.
fn run_native_dialog() -> DialogOutcome {
    let started = Instant::now();
    let extensions: Vec<&str> = Format::every_extension().collect();
    let choice = rfd::FileDialog::new().add_filter("animation", &extensions).add_filter("any file", &["*"]).pick_file();
    DialogOutcome::of(choice, started.elapsed())
}

/// bonescope's own file browser, shown in a window.
pub struct FileBrowser {
    /// The window's title: what the file is for.
    title: &'static str,
    folder: PathBuf,
    /// What the path field holds.
    typed: String,
    /// Sub-folders first, then animation files, each sorted by name.
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

impl FileBrowser {
    /// A browser titled `title` (what the file is for), in `folder`.
    pub fn new(title: &'static str, folder: &Path) -> Self {
        let (folder_now, typed, entries, error) = (PathBuf::new(), String::new(), Vec::new(), None);
        let mut browser = FileBrowser { title, folder: folder_now, typed, entries, error };
        browser.enter(folder);
        browser
    }

    fn enter(&mut self, folder: &Path) {
        match list(folder) {
            Ok(entries) => {
                self.folder = folder.to_owned();
                self.typed = folder.display().to_string();
                self.entries = entries;
                self.error = None;
            }
            Err(e) => self.error = Some(format!("{}: {e}", folder.display())),
        }
    }

    /// Follows a typed path: a folder is entered, anything else is the file to open.
    fn follow(&mut self, path: PathBuf) -> Option<PathBuf> {
        if path.is_dir() {
            self.enter(&path);
            None
        } else {
            Some(path)
        }
    }

    /// Draws the window; the file to open when one was chosen. `open` turns false when the window is closed.
    pub fn ui(&mut self, ctx: &egui::Context, open: &mut bool) -> Option<PathBuf> {
        let mut chosen = None;
        let mut still_open = *open;
        // One window whatever it is for: Open and Compare appear where the last one was left.
        let window = egui::Window::new(self.title).id(egui::Id::unique("file-browser"));
        window.open(&mut still_open).collapsible(false).default_width(480.0).show(ctx, |ui| {
            ui.horizontal(|ui| {
                if ui.button("Up").on_hover_text("the parent folder").clicked()
                    && let Some(parent) = self.folder.parent().map(Path::to_owned)
                {
                    self.enter(&parent);
                }
                let label = ui.label("Path");
                let field =
                    ui.add(egui::TextEdit::singleline(&mut self.typed).desired_width(360.0)).labelled_by(label.id);
                if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                    chosen = self.follow(PathBuf::from(self.typed.trim()));
                }
            });
            if let Some(error) = &self.error {
                ui.colored_label(egui::Color32::from_rgb(235, 64, 100), error);
            }
            ui.separator();
            egui::ScrollArea::vertical().max_height(320.0).show(ui, |ui| {
                for (name, is_folder) in self.entries.clone() {
                    let text = if is_folder { format!("{name}/") } else { name.clone() };
                    if ui.selectable_label(false, text).clicked() {
                        chosen = self.follow(self.folder.join(&name));
                    }
                }
                if self.entries.is_empty() {
                    ui.label(egui::RichText::new("no folders or animation files here").weak());
                }
            });
            ui.separator();
            if ui.button("Cancel").clicked() {
                *open = false;
            }
        });
        *open &= still_open;
        if chosen.is_some() {
            *open = false;
        }
        chosen
    }
}

/// What a chosen file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Purpose {
    Open,
    Compare,
}

/// The file dialog under way, if any: the desktop's (on its own thread, so the UI keeps drawing) or bonescope's.
pub struct Dialogs {
    /// Whether the desktop's dialog may be used (detected at start; tests set it).
    pub native: NativeDialog,
    pending: Option<(Receiver<DialogOutcome>, Purpose)>,
    browser: Option<(FileBrowser, Purpose)>,
    /// The folder the browser last showed: the next one, for either purpose, opens there.
    browsed: Option<PathBuf>,
}

impl Default for Dialogs {
    fn default() -> Self {
        Dialogs { native: NativeDialog::detect(), pending: None, browser: None, browsed: None }
    }
}

impl Dialogs {
    /// Asks for a file for `purpose`: the desktop's dialog where there is one, else bonescope's own browser in
    /// `folder`.
    pub fn choose(&mut self, purpose: Purpose, ctx: &egui::Context, folder: &Path, notes: &mut Notifications) {
        match self.native {
            NativeDialog::Available => self.pending = Some((spawn_native_dialog(ctx.clone()), purpose)),
            NativeDialog::Unavailable => self.browse(purpose, folder, notes),
        }
    }

    /// Shows bonescope's own file browser (the desktop has no dialog).
    fn browse(&mut self, purpose: Purpose, folder: &Path, notes: &mut Notifications) {
        notes.info("no desktop file dialog here (no XDG portal): using bonescope's own".to_owned());
        let title = match purpose {
            Purpose::Open => "Open a file",
            Purpose::Compare => "Compare with a file",
        };
        let folder = self.browsed.as_deref().filter(|f| f.is_dir()).unwrap_or(folder);
        self.browser = Some((FileBrowser::new(title, folder), purpose));
    }

    /// Draws the browser while it is open; the file chosen in either dialog, and what for. A desktop dialog that
    /// failed falls back to the browser.
    pub fn ui(&mut self, ctx: &egui::Context, folder: &Path, notes: &mut Notifications) -> Option<(PathBuf, Purpose)> {
        if let Some((dialog, purpose)) = &self.pending
            && let Ok(outcome) = dialog.try_recv()
        {
            let purpose = *purpose;
            self.pending = None;
            match outcome {
                DialogOutcome::Chosen(path) => return Some((path, purpose)),
                DialogOutcome::Cancelled => {}
                DialogOutcome::Failed => {
                    self.native = NativeDialog::Unavailable;
                    self.browse(purpose, folder, notes);
                }
            }
        }
        let (browser, purpose) = self.browser.as_mut()?;
        let mut open = true;
        let chosen = browser.ui(ctx, &mut open).map(|path| (path, *purpose));
        self.browsed = Some(browser.folder.clone());
        if !open {
            self.browser = None;
        }
        chosen
    }
}

/// Runs the native file dialog on its own thread so the UI keeps drawing.
fn spawn_native_dialog(ctx: egui::Context) -> Receiver<DialogOutcome> {
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = sender.send(run_native_dialog());
        ctx.request_repaint();
    });
    receiver
}

/// A folder's sub-folders and animation files (hidden ones left out), folders first, each sorted.
fn list(folder: &Path) -> std::io::Result<Vec<(String, bool)>> {
    let mut entries = Vec::new();
    for entry in std::fs::read_dir(folder)? {
        let Ok(entry) = entry else { continue };
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let is_folder = entry.path().is_dir();
        if is_folder || Format::named_by(Path::new(&name)).is_some() {
            entries.push((name, is_folder));
        }
    }
    entries.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.to_lowercase().cmp(&b.0.to_lowercase())));
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dialog_gone_at_once_failed_and_one_left_open_was_cancelled() {
        assert_eq!(DialogOutcome::of(None, Duration::from_millis(5)), DialogOutcome::Failed);
        assert_eq!(DialogOutcome::of(None, Duration::from_secs(3)), DialogOutcome::Cancelled);
        let path = PathBuf::from("a.glb");
        assert_eq!(DialogOutcome::of(Some(path.clone()), Duration::ZERO), DialogOutcome::Chosen(path));
    }

    #[test]
    fn folders_first_then_animation_files() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["b.fbx", "a.GLB", "notes.txt", ".hidden.bvh"] {
            std::fs::write(dir.path().join(name), b"").unwrap();
        }
        std::fs::create_dir(dir.path().join("takes")).unwrap();
        let names: Vec<(String, bool)> = list(dir.path()).unwrap();
        assert_eq!(names, [("takes".into(), true), ("a.GLB".into(), false), ("b.fbx".into(), false)]);
    }
}
