//! The work: everything computed off the UI thread, in one place that starts it when what it depends on changes
//! (each result keyed by the rig's identity, a [`Setup`](crate::eval::Setup) and the request: [`Key`]), stops what
//! is no longer wanted, and waits for it where a settled state is wanted (tests, headless renders). Panels ask it for
//! results; they own no threads.

use std::sync::Arc;

use super::compared::Compared;
use super::document::Document;
use super::identity::RigId;
use super::job::{Job, Key, Progress};
use crate::analysis::storage::{StorageOptions, StorageReport, storage_report};
use crate::analysis::{
    BindCheck, BindTolerance, ClipAnalysis, Components, CurveRequest, Judged, ScanOptions, Tolerances, analyze,
    check_bind,
};
use crate::diff::{Frames, Pairs, compare, comparison_times, model_curves};
use crate::eval::{Evaluation, Setup};
use crate::explain::{Costs, Explanation, Question, Scale, explain};
use crate::model::Rig;

/// What a whole-clip analysis is asked.
#[derive(Clone, Debug, PartialEq)]
pub struct AnalysisRequest {
    /// What the ghost evaluates of the same rig (its curves are plotted dashed).
    pub ghost: Option<Setup>,
    pub plotted: Vec<usize>,
    /// How the clip is sampled and judged.
    pub options: ScanOptions,
    /// Every bone (the summary), or only the plotted bones' chains (their curves).
    pub judged: Judged,
}

/// What an explanation is asked: the bone, how the clip is sampled and judged (as the whole-clip analysis samples
/// and judges it, so that both flag the same samples), and which fixes are costed.
#[derive(Clone, Debug, PartialEq)]
struct WhyRequest {
    bone: usize,
    options: ScanOptions,
    costs: Costs,
}

/// Which of the two explanation jobs.
#[derive(Clone, Copy)]
enum Which {
    Best,
    Every,
}

/// What a comparison with the compared file is asked: that file (this pairing of it) as evaluated, and how often
/// the clip is sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct CompareRequest {
    pub compared: RigId,
    pub setup: Setup,
    pub rate: f64,
}

/// What the compared file's curves are asked: the document's bones plotted, at the times of the document's own
/// curves (the dashed curves share their axis). Keyed by the compared file as evaluated.
#[derive(Clone, Debug, PartialEq)]
pub struct CurvesRequest {
    pub plotted: Vec<usize>,
    pub times: Vec<f64>,
}

/// Each document bone's largest difference from the compared file over the clip.
#[derive(Clone, Debug, PartialEq)]
pub struct LargestDifferences {
    /// Per document bone: the largest distance of its origin and axis probes, as a fraction of the rig's size
    /// (`None` without a partner, and for conversion nodes).
    pub bones: Vec<Option<f64>>,
    pub rig_size: f64,
}

/// `(document bone, its partner's model-space components at the curves' times)` for the plotted bones that have one.
pub type ComparedCurves = Vec<(usize, Vec<Components>)>;

/// What the window asks to be analysed this frame.
pub struct Wanted<'a> {
    pub doc: &'a Document,
    pub tolerances: Tolerances,
    /// The bones whose curves are plotted (none: no curves wanted).
    pub plotted: Vec<usize>,
}

/// The latest results the panels show (possibly for an older state while a newer one is computed).
#[derive(Clone, Default)]
pub struct Results {
    /// The rig-wide analysis: every bone's summary and stretched samples.
    pub analysis: Option<Arc<ClipAnalysis>>,
    /// The plotted bones' curves (a separate, quick analysis of their chains).
    pub curves: Option<Arc<ClipAnalysis>>,
    /// `(done, total)` samples while the whole-clip analysis runs.
    pub progress: Option<(usize, usize)>,
    /// Each bone's largest difference from the compared file over the clip.
    pub differences: Option<Arc<LargestDifferences>>,
    /// The compared file's curves of the plotted bones.
    pub compared_curves: Option<Arc<ComparedCurves>>,
}

/// Every background job of the app.
#[derive(Default)]
pub struct Work {
    analysis: Job<Key<AnalysisRequest>, ClipAnalysis>,
    curves: Job<Key<AnalysisRequest>, ClipAnalysis>,
    differences: Job<Key<CompareRequest>, LargestDifferences>,
    compared_curves: Job<Key<CurvesRequest>, ComparedCurves>,
    bind: Job<Key<()>, BindCheck>,
    storage: Job<Key<()>, StorageReport>,
    /// The size of what the window analyses over its clip, which every Why? of it compares changes at: measured
    /// once the analysis flags a bone, before one is asked about.
    scale: Job<Key<ScanOptions>, Scale>,
    /// The explained bone's best fix first (`explain::Costs::Best`, a fraction of the time), then every fix ranked.
    best_fix: Job<Key<WhyRequest>, Explanation>,
    explanation: Job<Key<WhyRequest>, Explanation>,
    /// The bone last explained and its options: what [`Work::settle`] explains to the end.
    why_asked: Option<(usize, ScanOptions)>,
    /// Woken when a job finishes, so that the UI shows its result.
    waker: Option<egui::Context>,
}

impl Work {
    pub fn wake(&mut self, ctx: egui::Context) {
        self.waker = Some(ctx);
    }

    /// `job` computing `work()` for `key`, started when `key` is not the one it has or computes (see [`Job::update`]).
    fn start<K, T, W>(waker: &Option<egui::Context>, job: &mut Job<K, T>, key: K, work: impl FnOnce() -> W)
    where
        K: Clone + PartialEq + Send + 'static,
        T: Send + Sync + 'static,
        W: FnOnce(&Progress) -> Option<T> + Send + 'static,
    {
        let waker = waker.clone();
        job.update(key, work, move || waker.iter().for_each(egui::Context::request_repaint));
    }

    /// Starts what `wanted` needs: the rig-wide analysis, the plotted bones' curves, and with a compared file the
    /// differences and its curves (each only when its key changed).
    pub fn analyse(&mut self, wanted: &Wanted) {
        let rig = &wanted.doc.rig;
        let key = analysis_key(wanted);
        Work::start(&self.waker, &mut self.analysis, key.clone(), || analysis(key.clone(), rig.clone()));
        self.measure_scale(&key, rig);
        if let Some(key) = curves_key(wanted) {
            Work::start(&self.waker, &mut self.curves, key.clone(), || analysis(key, rig.clone()));
        }
        let Some(compared) = wanted.doc.compared.clone() else { return };
        let key = compare_key(wanted.doc, &compared);
        Work::start(&self.waker, &mut self.differences, key.clone(), || {
            differences(key, rig.clone(), compared.clone())
        });
        if let Some(key) = self.compared_curves_key(wanted) {
            Work::start(&self.waker, &mut self.compared_curves, key.clone(), || compared_curves(key, compared));
        }
    }

    /// Measures the scale of what the analysis `analysed` evaluates once it is done and flags a bone: what the Why? of
    /// any bone would otherwise measure first.
    fn measure_scale(&mut self, analysed: &Key<AnalysisRequest>, rig: &Arc<Rig>) {
        self.analysis.collect();
        let flagged = self.analysis.for_key(analysed).is_some_and(|a| a.scan.bones.iter().any(|b| b.stretched()));
        if flagged {
            let key = analysed.asking(analysed.request.options);
            let (rig, measured) = (rig.clone(), key.clone());
            let work = || move |_: &Progress| Some(Scale::of(&measured.evaluation(&rig)?, measured.request.rate));
            Work::start(&self.waker, &mut self.scale, key, work);
        }
    }

    /// What the compared file's curves depend on: the compared file as evaluated, the plotted bones, and the times
    /// of the document's own curves, once they are there.
    fn compared_curves_key(&self, wanted: &Wanted) -> Option<Key<CurvesRequest>> {
        let times = self.curves.for_key(&curves_key(wanted)?)?.times.clone();
        let compare = compare_key(wanted.doc, wanted.doc.compared.as_ref()?);
        let request = CurvesRequest { plotted: wanted.plotted.clone(), times };
        Some(Key { rig: compare.request.compared, setup: compare.request.setup, request })
    }

    /// The latest results, for the panels; a comparison's only while there is one.
    pub fn results(&self, doc: &Document) -> Results {
        let comparing = doc.compared.is_some();
        Results {
            analysis: self.analysis.latest().map(|(_, a)| a.clone()),
            curves: self.curves.latest().map(|(_, c)| c.clone()),
            progress: self.analysis.progress(),
            differences: self.differences.latest().filter(|_| comparing).map(|(_, d)| d.clone()),
            compared_curves: self.compared_curves.latest().filter(|_| comparing).map(|(_, c)| c.clone()),
        }
    }

    /// The whole-clip analysis of what `wanted` shows, if computed.
    pub fn analysis(&self, wanted: &Wanted) -> Option<&Arc<ClipAnalysis>> {
        self.analysis.for_key(&analysis_key(wanted))
    }

    /// The plotted bones' curves of what `wanted` shows, if computed.
    pub fn curves(&self, wanted: &Wanted) -> Option<&Arc<ClipAnalysis>> {
        self.curves.for_key(&curves_key(wanted)?)
    }

    /// Each bone's largest difference from the compared file, if computed for what `wanted` shows.
    pub fn differences(&self, wanted: &Wanted) -> Option<&Arc<LargestDifferences>> {
        self.differences.for_key(&compare_key(wanted.doc, wanted.doc.compared.as_ref()?))
    }

    /// The bind check of `doc`'s clip as authored: started when it changed, `None` until done.
    pub fn bind_check(&mut self, doc: &Document) -> Option<&Arc<BindCheck>> {
        // The check reads the clip as authored: its key leaves the layers out.
        let key = Key::authored(doc, ());
        let (rig, checked) = (doc.rig.clone(), key.clone());
        let work = || move |_: &Progress| Some(check_bind(&checked.evaluation(&rig)?, &BindTolerance::default()));
        Work::start(&self.waker, &mut self.bind, key.clone(), work);
        self.bind.for_key(&key)
    }

    /// Starts measuring the stretch-quaternion storage of what `doc` evaluates.
    pub fn measure_storage(&mut self, doc: &Document) {
        let key = Key::of(doc, ());
        let (rig, measured) = (doc.rig.clone(), key.clone());
        let work = || move |_: &Progress| Some(storage_report(&measured.evaluation(&rig)?, &StorageOptions::default()));
        Work::start(&self.waker, &mut self.storage, key, work);
    }

    /// The storage report of what `doc` evaluates, once measured; and whether a measurement is under way.
    pub fn storage(&mut self, doc: &Document) -> (Option<&Arc<StorageReport>>, bool) {
        self.storage.collect();
        let running = self.storage.progress().is_some();
        (self.storage.for_key(&Key::of(doc, ())), running)
    }

    /// `bone` of what `doc` evaluates explained (the clip sampled and judged with `options`), as far as it is known,
    /// from the window's whole-clip analysis of it (`None` until that is done): its best fix first ([`Costs::Best`]),
    /// then every fix ranked ([`Costs::Every`], started once the first is done, so that it takes no core from it).
    /// Each is started when asked anew (one at a time: it cannot stop half way, so a newer one waits for the one
    /// under way to finish); the flag says whether the ranking is complete.
    pub fn explanation(
        &mut self,
        doc: &Document,
        bone: usize,
        options: ScanOptions,
    ) -> Option<(Arc<Explanation>, bool)> {
        self.why_asked = Some((bone, options));
        let analysed =
            Key::of(doc, AnalysisRequest { ghost: None, plotted: Vec::new(), options, judged: Judged::Every });
        self.analysis.collect();
        let before = self.analysis.for_key(&analysed)?.clone();
        self.scale.collect();
        let scale = self.scale.for_key(&analysed.asking(options)).cloned();
        let best = Key::of(doc, WhyRequest { bone, options, costs: Costs::Best });
        let every = Key { request: WhyRequest { costs: Costs::Every, ..best.request.clone() }, ..best.clone() };
        self.explain(Which::Best, best.clone(), doc.rig.clone(), before.clone(), scale.clone());
        let first = self.best_fix.for_key(&best)?.clone();
        self.explain(Which::Every, every.clone(), doc.rig.clone(), before, scale);
        Some(match self.explanation.for_key(&every) {
            Some(ranked) => (ranked.clone(), true),
            None => (first, false),
        })
    }

    /// Starts the explanation `key` asks of `rig` in its job, given the clip's analysis `before` and its scale where
    /// measured, unless that job is busy with another.
    fn explain(
        &mut self,
        which: Which,
        key: Key<WhyRequest>,
        rig: Arc<Rig>,
        before: Arc<ClipAnalysis>,
        scale: Option<Arc<Scale>>,
    ) {
        let job = match which {
            Which::Best => &mut self.best_fix,
            Which::Every => &mut self.explanation,
        };
        if !job.busy_with_other(&key) {
            let explained = key.clone();
            let work = || move |_: &Progress| explanation(&rig, &explained, &before, scale.as_deref());
            Work::start(&self.waker, job, key, work);
        }
    }

    /// Whether the analyses of the window's state are still being computed.
    pub fn analysing(&self) -> bool {
        [self.analysis.progress(), self.curves.progress(), self.differences.progress(), self.compared_curves.progress()]
            .iter()
            .any(Option::is_some)
    }

    /// Waits for every job under way, starting what `wanted` needs first (the compared curves wait for the
    /// document's, the scale for the analysis).
    pub fn settle(&mut self, wanted: &Wanted) {
        self.analyse(wanted);
        self.analysis.wait();
        self.curves.wait();
        self.differences.wait();
        self.analyse(wanted);
        self.scale.wait();
        self.compared_curves.wait();
        self.bind.wait();
        self.storage.wait();
        if let Some((bone, options)) = self.why_asked {
            self.explanation(wanted.doc, bone, options);
            self.best_fix.wait();
            self.explanation(wanted.doc, bone, options);
            self.explanation.wait();
        }
    }
}

/// The rig-wide analysis the window wants: every bone judged over the clip, no curves. It does not change with the
/// selection, so selecting a bone never waits for it.
fn analysis_key(wanted: &Wanted) -> Key<AnalysisRequest> {
    let options = ScanOptions { rate: wanted.doc.analysis_rate(), tolerances: wanted.tolerances };
    let request = AnalysisRequest { ghost: None, plotted: Vec::new(), options, judged: Judged::Every };
    Key::of(wanted.doc, request)
}

/// The curves the plots want: the plotted bones (and the ghost's), only their chains evaluated; `None` with
/// nothing plotted.
fn curves_key(wanted: &Wanted) -> Option<Key<AnalysisRequest>> {
    let mut key = analysis_key(wanted);
    key.request.plotted = wanted.plotted.clone();
    key.request.ghost = wanted.doc.ghost_setup();
    key.request.judged = Judged::CurveChains;
    (!key.request.plotted.is_empty()).then_some(key)
}

/// The comparison of `doc` with `compared` at the analysis's rate.
fn compare_key(doc: &Document, compared: &Compared) -> Key<CompareRequest> {
    let setup = compared.setup(doc.setup().clip);
    Key::of(doc, CompareRequest { compared: compared.rig_id, setup, rate: doc.analysis_rate() })
}

/// The analysis `key` asks of `rig` (the rig `key` was made of), as work for a [`Job`].
fn analysis(
    key: Key<AnalysisRequest>,
    rig: Arc<Rig>,
) -> impl FnOnce(&Progress) -> Option<ClipAnalysis> + Send + 'static {
    move |progress| {
        let evaluation = key.evaluation(&rig)?;
        let request = &key.request;
        let ghost = request.ghost.as_ref().and_then(|ghost| Evaluation::of(&rig, ghost).ok());
        let curves = CurveRequest { bones: &request.plotted, ghost: ghost.as_ref(), judged: request.judged };
        let report = |done: usize, total: usize| progress.report(done, total);
        analyze(&evaluation, curves, &request.options, &report, progress.cancelled())
    }
}

/// The bone `key` asks of `rig` explained, as `bonescope explain` explains it, given the clip's analysis `before` (the
/// window's: the same setup and options) and its scale where measured.
fn explanation(rig: &Rig, key: &Key<WhyRequest>, before: &ClipAnalysis, scale: Option<&Scale>) -> Option<Explanation> {
    let evaluation = key.evaluation(rig)?;
    let (bone, options) = (key.request.bone, &key.request.options);
    let question = Question { bones: Some(&[bone]), costs: key.request.costs, scale, ..Question::default() };
    explain(&evaluation, before, question, options).pop()
}

/// The differences `key` asks for, as work for a [`Job`]: the document's rig (the one `key` was made of) against
/// `compared`.
fn differences(
    key: Key<CompareRequest>,
    rig: Arc<Rig>,
    compared: Arc<Compared>,
) -> impl FnOnce(&Progress) -> Option<LargestDifferences> + Send + 'static {
    move |_| {
        let own = key.evaluation(&rig)?;
        let other = Evaluation::of(&compared.rig, &key.request.setup).ok()?;
        // The badges need the bones alone: skinning every paired mesh at every time would be thrown away. Two files'
        // frames are compared up to their exporters' conventions, as `diff` compares them.
        let pairs = Pairs { meshes: Vec::new(), frames: Frames::UpToConvention, ..Pairs::by_name(&own, &other) };
        let comparison = compare(&own, &other, &pairs, &comparison_times(&own, &other, key.request.rate));
        let mut bones = vec![None; rig.skeleton.len()];
        for difference in &comparison.bones {
            bones[difference.a] = Some(difference.probe.max / comparison.rig_size);
        }
        Some(LargestDifferences { bones, rig_size: comparison.rig_size })
    }
}

/// The compared curves `key` asks for, as work for a [`Job`].
fn compared_curves(
    key: Key<CurvesRequest>,
    compared: Arc<Compared>,
) -> impl FnOnce(&Progress) -> Option<ComparedCurves> + Send + 'static {
    move |_| {
        let request = &key.request;
        let paired: Vec<(usize, usize)> =
            request.plotted.iter().filter_map(|&b| compared.bones.get(b).copied().flatten().map(|p| (b, p))).collect();
        let partners: Vec<usize> = paired.iter().map(|&(_, p)| p).collect();
        let curves = model_curves(&key.evaluation(&compared.rig)?, &partners, &request.times);
        Some(paired.into_iter().map(|(b, _)| b).zip(curves).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_best_fix_comes_first_then_every_fix_ranked() {
        // The demo's forearm: nothing known at first; once its best-fix job is done the explanation has that fix
        // (and only the fixes it took to find it); the ranking that follows has every fix, the same one first.
        let doc = Document::demo();
        let forearm = doc.rig.skeleton.find("forearm").unwrap();
        let options = ScanOptions::default();
        let mut work = Work::default();
        let wanted = Wanted { doc: &doc, tolerances: options.tolerances, plotted: Vec::new() };
        assert!(work.explanation(&doc, forearm, options).is_none(), "nothing is known before the analysis");
        work.analyse(&wanted);
        work.analysis.wait();
        assert!(work.explanation(&doc, forearm, options).is_none(), "nothing is known before the first job ends");
        work.best_fix.wait();
        let (first, _) = work.explanation(&doc, forearm, options).expect("the best fix is known");
        work.explanation.wait();
        let (ranked, ranked_complete) = work.explanation(&doc, forearm, options).expect("the ranking is known");
        assert!(ranked_complete, "the ranking is complete once its job ends");
        let change = |e: &Explanation| e.best_fix().map(|fix| fix.change);
        assert_eq!(change(&first), change(&ranked), "the first answer is the ranking's best");
        assert!(first.best_fix().is_some() && first.fixes.len() < ranked.fixes.len(), "{}", first.fixes.len());
        assert_eq!(first.headline(doc.rig.unit), ranked.headline(doc.rig.unit), "the same line heads both");
    }
}
