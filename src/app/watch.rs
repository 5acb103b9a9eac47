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
}

impl FileWatcher {
    /// Watches `path`; `None` when the platform cannot (the app then simply does not auto-reload).
    pub fn new(path: &Path, wake: impl Fn(Duration) + Send + 'static) -> Option<Self> {
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
                wake(SETTLE);
            }
        })
        .ok()?;
        watcher.watch(folder, RecursiveMode::NonRecursive).ok()?;
        Some(FileWatcher { _watcher: watcher, last_event })
    }

    /// Whether the file changed and has been quiet since; resets when it says so.
    pub fn changed(&self) -> bool {
        let Ok(mut last) = self.last_event.lock() else { return false };
        match *last {
            Some(at) if at.elapsed() >= SETTLE => {
                *last = None;
                true
            }
            _ => false,
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
}
