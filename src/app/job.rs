//! The whole-clip analysis, computed off the UI thread and cached until the file, clip, modes or plotted bones
//! change.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, channel};

use super::Ghost;
use crate::analysis::{
    ClipAnalysis, CurveRequest, GhostRequest, Judged, Layered, ScanOptions, Subject, Tolerances, analyze,
};
use crate::eval::{Hierarchy, LayerStack, Layers};
use crate::model::{InheritMode, Rig};

/// Everything the result depends on.
#[derive(Clone, Debug, PartialEq)]
pub struct JobKey {
    /// Changes whenever a (re)loaded rig replaces the document's.
    pub generation: u64,
    pub clip: Option<usize>,
    pub modes: Vec<InheritMode>,
    pub ghost: Option<Ghost>,
    pub layers: Layers,
    pub plotted: Vec<usize>,
    pub rate: f64,
    pub tolerances: Tolerances,
    /// Every bone (the summary), or only the plotted bones' chains (their curves).
    pub judged: Judged,
}

struct Running {
    key: JobKey,
    done: Arc<AtomicUsize>,
    total: Arc<AtomicUsize>,
    cancel: Arc<AtomicBool>,
    result: Receiver<Option<ClipAnalysis>>,
}

/// The latest finished analysis and the one being computed, if any.
#[derive(Default)]
pub struct AnalysisJob {
    finished: Option<(JobKey, Arc<ClipAnalysis>)>,
    running: Option<Running>,
}

impl AnalysisJob {
    /// Starts a new analysis when `key` differs from the finished or running one; collects a finished result.
    /// `on_done` is called from the worker when it finishes (to wake the UI).
    pub fn update(&mut self, key: JobKey, rig: &Arc<Rig>, on_done: impl Fn() + Send + 'static) {
        self.collect();
        let current = self.running.as_ref().map(|r| &r.key).or(self.finished.as_ref().map(|(k, _)| k));
        if current == Some(&key) {
            return;
        }
        if let Some(old) = self.running.take() {
            old.cancel.store(true, Ordering::Relaxed);
        }
        self.running = Some(spawn(key, rig.clone(), on_done));
    }

    fn collect(&mut self) {
        let Some(running) = &self.running else { return };
        match running.result.try_recv() {
            Ok(Some(analysis)) => {
                let running = self.running.take().expect("checked above");
                self.finished = Some((running.key, Arc::new(analysis)));
            }
            Ok(None) | Err(std::sync::mpsc::TryRecvError::Disconnected) => self.running = None,
            Err(std::sync::mpsc::TryRecvError::Empty) => {}
        }
    }

    /// The latest finished analysis (possibly for an older key while a new one runs).
    pub fn latest(&self) -> Option<&(JobKey, Arc<ClipAnalysis>)> {
        self.finished.as_ref()
    }

    /// `(done, total)` samples of the running analysis.
    pub fn progress(&self) -> Option<(usize, usize)> {
        self.running.as_ref().map(|r| (r.done.load(Ordering::Relaxed), r.total.load(Ordering::Relaxed)))
    }

    /// Waits for the running analysis (tests and headless renders want a settled state).
    pub fn wait(&mut self) {
        if let Some(running) = self.running.take()
            && let Ok(Some(analysis)) = running.result.recv()
        {
            self.finished = Some((running.key, Arc::new(analysis)));
        }
    }
}

fn spawn(key: JobKey, rig: Arc<Rig>, on_done: impl Fn() + Send + 'static) -> Running {
    let (sender, result) = channel();
    let done = Arc::new(AtomicUsize::new(0));
    let total = Arc::new(AtomicUsize::new(0));
    let cancel = Arc::new(AtomicBool::new(false));
    let (job_key, job_done, job_total, job_cancel) = (key.clone(), done.clone(), total.clone(), cancel.clone());
    std::thread::spawn(move || {
        let hierarchy = Hierarchy::new(&rig.skeleton, &job_key.modes);
        // `(modes, unlayered)`.
        let ghost_modes = job_key.ghost.map(|ghost| {
            let (modes, layered) = ghost.evaluation(&job_key.modes, &rig.skeleton);
            (modes, !layered)
        });
        let ghost_hierarchy = ghost_modes.as_ref().map(|(modes, _)| Hierarchy::new(&rig.skeleton, modes));
        let ghost = ghost_hierarchy
            .as_ref()
            .zip(ghost_modes.as_ref())
            .map(|(hierarchy, (_, unlayered))| GhostRequest { hierarchy, unlayered: *unlayered });
        let clip = job_key.clip.and_then(|c| rig.clips.get(c));
        let options = ScanOptions { rate: job_key.rate, tolerances: job_key.tolerances };
        let request = CurveRequest { bones: &job_key.plotted, ghost, judged: job_key.judged };
        let progress = |d: usize, t: usize| {
            job_done.store(d, Ordering::Relaxed);
            job_total.store(t, Ordering::Relaxed);
        };
        // The document checked the layers against this rig; without layers the plain analysis is the same.
        let stack = LayerStack::new(&rig, &job_key.layers).ok().filter(|_| !job_key.layers.is_empty());
        let subject = match &stack {
            Some(layers) => Subject::layered(Layered { rig: &rig, layers }, clip),
            None => Subject::clip(&rig.skeleton, clip),
        };
        let analysis = analyze(subject, &hierarchy, request, &options, &progress, &job_cancel);
        // The receiver may be gone (a newer job replaced this one): nothing to do then.
        let _ = sender.send(analysis);
        on_done();
    });
    Running { key, done, total, cancel, result }
}
