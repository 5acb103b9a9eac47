//! Watching the open file so a re-export shows up by itself.
//!
//! The folder is watched rather than the file: exporters often write a temporary file and rename it over the old
//! one, which a watch on the file itself would lose. Events settle for a moment before a reload, since a write
//! arrives as several events.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use notify::{RecommendedWatcher, RecursiveMode, Watcher};

/// How long the file must stay quiet before it is reloaded.
const SETTLE: Duration = Duration::from_millis(300);

pub struct FileWatcher {
    _watcher: RecommendedWatcher,
    last_event: Arc<Mutex<Option<Instant>>>,
    /// Wakes the UI after the given time (from the watcher's thread, and again from `changed`).
    wake: Arc<dyn Fn(Duration) + Send + Sync>,
}

impl FileWatcher {
    /// Watches `path`; `None` when the platform cannot (the app then simply does not auto-reload).
    pub fn new(path: &Path, wake: impl Fn(Duration) + Send + Sync + 'static) -> Option<Self> {
        let wake: Arc<dyn Fn(Duration) + Send + Sync> = Arc::new(wake);
        let waker = wake.clone();
        let file: PathBuf = path.file_name()?.into();
        let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let last_event = Arc::new(Mutex::new(None));
        let sink = last_event.clone();
        let mut watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
            let Ok(event) = event else { return };
            let ours = event.paths.iter().any(|p| p.file_name() == Some(file.as_os_str()));
            if ours && (event.kind.is_modify() || event.kind.is_create()) {
                if let Ok(mut last) = sink.lock() {
                    *last = Some(Instant::now());
                }
                waker(SETTLE);
            }
        })
        .ok()?;
        watcher.watch(folder, RecursiveMode::NonRecursive).ok()?;
        Some(FileWatcher { _watcher: watcher, last_event, wake })
    }

    /// Whether the file changed and has been quiet since; resets when it says so. A change still settling wakes
    /// the UI again when it will have settled: the wake-up asked for at its first event may come before the last
    /// one's quiet time is over (the UI keeps the earliest wake-up asked for), and nothing else would come.
    pub fn changed(&self) -> bool {
        let Ok(mut last) = self.last_event.lock() else { return false };
        match *last {
            Some(at) if at.elapsed() >= SETTLE => {
                *last = None;
                true
            }
            Some(at) => {
                (self.wake)(SETTLE - at.elapsed());
                false
            }
            None => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rewrite_is_noticed_once_it_settles() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rig.glb");
        std::fs::write(&path, b"one").unwrap();
        let watcher = FileWatcher::new(&path, |_| {}).expect("inotify works here");
        std::fs::write(dir.path().join("other.txt"), b"not ours").unwrap();
        std::fs::write(&path, b"two").unwrap();
        let deadline = Instant::now() + Duration::from_secs(5);
        while !watcher.changed() {
            assert!(Instant::now() < deadline, "no change noticed");
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(!watcher.changed(), "reported once");
    }

    #[test]
    fn a_change_still_settling_asks_to_be_looked_at_again() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rig.glb");
        std::fs::write(&path, b"one").unwrap();
        let wakes = Arc::new(Mutex::new(Vec::new()));
        let sink = wakes.clone();
        let watcher = FileWatcher::new(&path, move |after| sink.lock().unwrap().push(after)).expect("inotify");
        std::fs::write(&path, b"two").unwrap();
        let deadline = Instant::now() + Duration::from_secs(5);
        while wakes.lock().unwrap().is_empty() {
            assert!(Instant::now() < deadline, "no event");
            std::thread::sleep(Duration::from_millis(5));
        }
        // Looked at before the change settled: not yet, and a wake-up for the rest of the quiet time.
        let before = wakes.lock().unwrap().len();
        assert!(!watcher.changed());
        let wakes = wakes.lock().unwrap();
        assert_eq!(wakes.len(), before + 1);
        assert!(*wakes.last().unwrap() <= SETTLE);
    }
}
