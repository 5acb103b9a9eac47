//! One piece of work computed off the UI thread, kept until what it depends on changes ([`Key`]), cancelled when a
//! newer one replaces it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, channel};

use super::document::Document;
use super::identity::RigId;
use crate::eval::{Evaluation, Layers, Setup};
use crate::model::Rig;

/// How far a piece of work has come, and whether it should stop (a newer one replaced it).
#[derive(Clone, Default)]
pub struct Progress {
    done: Arc<AtomicUsize>,
    total: Arc<AtomicUsize>,
    cancel: Arc<AtomicBool>,
}

impl Progress {
    pub fn report(&self, done: usize, total: usize) {
        self.done.store(done, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    /// Set when the work is no longer wanted.
    pub fn cancelled(&self) -> &AtomicBool {
        &self.cancel
    }
}

struct Running<K, T> {
    key: K,
    progress: Progress,
    result: Receiver<Option<T>>,
}

/// The latest finished result of a piece of work keyed by `K`, and the one being computed, if any.
pub struct Job<K, T> {
    finished: Option<(K, Arc<T>)>,
    running: Option<Running<K, T>>,
}

impl<K, T> Default for Job<K, T> {
    fn default() -> Self {
        Job { finished: None, running: None }
    }
}

impl<K: Clone + PartialEq + Send + 'static, T: Send + Sync + 'static> Job<K, T> {
    /// Starts the work `work()` makes on a thread when `key` differs from the finished or running one (a running
    /// one is cancelled); collects a finished result. The work is only made then: the UI asks every frame, and
    /// making it copies what it works on. `on_done` is called from the worker when it finishes (to wake the UI).
    /// The work returns `None` when it was cancelled.
    pub fn update<W: FnOnce(&Progress) -> Option<T> + Send + 'static>(
        &mut self,
        key: K,
        work: impl FnOnce() -> W,
        on_done: impl Fn() + Send + 'static,
    ) {
        self.collect();
        let current = self.running.as_ref().map(|r| &r.key).or(self.finished.as_ref().map(|(k, _)| k));
        if current == Some(&key) {
            return;
        }
        if let Some(old) = self.running.take() {
            old.progress.cancel.store(true, Ordering::Relaxed);
        }
        let work = work();
        let (sender, result) = channel();
        let progress = Progress::default();
        let worker_progress = progress.clone();
        std::thread::spawn(move || {
            // The receiver may be gone (a newer job replaced this one): nothing to do then.
            let _ = sender.send(work(&worker_progress));
            on_done();
        });
        self.running = Some(Running { key, progress, result });
    }

    /// Whether work for another key than `key` is still running; if so it is asked to stop (it stops where it
    /// checks). Work that cannot stop half way waits for this before [`Job::update`], so that at most one runs.
    pub fn busy_with_other(&mut self, key: &K) -> bool {
        self.collect();
        match &self.running {
            Some(running) if running.key != *key => {
                running.progress.cancel.store(true, Ordering::Relaxed);
                true
            }
            _ => false,
        }
    }

    /// Takes the running work's result if it has finished.
    pub fn collect(&mut self) {
        let Some(running) = &self.running else { return };
        match running.result.try_recv() {
            Ok(Some(result)) => {
                let running = self.running.take().expect("checked above");
                self.finished = Some((running.key, Arc::new(result)));
            }
            Ok(None) | Err(std::sync::mpsc::TryRecvError::Disconnected) => self.running = None,
            Err(std::sync::mpsc::TryRecvError::Empty) => {}
        }
    }

    /// The latest finished result (possibly for an older key while a new one runs).
    pub fn latest(&self) -> Option<&(K, Arc<T>)> {
        self.finished.as_ref()
    }

    /// The latest finished result if it is for `key`.
    pub fn for_key(&self, key: &K) -> Option<&Arc<T>> {
        self.finished.as_ref().filter(|(k, _)| k == key).map(|(_, result)| result)
    }

    /// `(done, total)` of the running work.
    pub fn progress(&self) -> Option<(usize, usize)> {
        let progress = &self.running.as_ref()?.progress;
        Some((progress.done.load(Ordering::Relaxed), progress.total.load(Ordering::Relaxed)))
    }

    /// Waits for the running work (tests and headless renders want a settled state).
    pub fn wait(&mut self) {
        if let Some(running) = self.running.take()
            && let Ok(Some(result)) = running.result.recv()
        {
            self.finished = Some((running.key, Arc::new(result)));
        }
    }
}

/// What a result computed of a rig depends on: the rig (this load of it, [`RigId`]), what is evaluated of it, and
/// what is asked of that evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Key<R> {
    pub rig: RigId,
    pub setup: Setup,
    pub request: R,
}

impl<R> Key<R> {
    /// `request` of what `doc` evaluates.
    pub fn of(doc: &Document, request: R) -> Self {
        Key { rig: doc.rig_id, setup: doc.setup().clone(), request }
    }

    /// `request` of the clip as authored, which no layer changes (the bind check): a layer edit, a dragged weight
    /// slider, starts no new one.
    pub fn authored(doc: &Document, request: R) -> Self {
        Key { setup: Setup { layers: Layers::default(), ..doc.setup().clone() }, ..Key::of(doc, request) }
    }

    /// Another request of what this key evaluates.
    pub fn asking<S>(&self, request: S) -> Key<S> {
        Key { rig: self.rig, setup: self.setup.clone(), request }
    }

    /// The evaluation the key's setup makes of `rig` (the rig the key was made of); `None` if it does not fit.
    pub fn evaluation<'a>(&self, rig: &'a Rig) -> Option<Evaluation<'a>> {
        Evaluation::of(rig, &self.setup).ok()
    }
}
