//! `bonescope scan`: whole clips of several files, the stretched bones of each; or, with `--compare-inherit`, how
//! far every bone moves between two sets of inheritance modes.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Args, ValueEnum};

use super::layers::LayerArgs;
use super::options::{clip_index, files_help, parse_angle, parse_comparison, parse_rate};
use super::setup::evaluation;
use super::table::{Table, frame_at, shown};
use super::{EvalArgs, ToleranceArgs};
use crate::analysis::ScanOptions;
use crate::analysis::report::{AnimationInfo, AnimationScan, FileReport, FileScan};
use crate::analysis::storage::{RuntimeError, StorageOptions, StorageReport, storage_report};
use crate::diff::{Align, AnimationDiff, Clips, FileSide, diff_files};
use crate::eval::{Evaluation, Setup};
use crate::explain::scan_clip;
use crate::import;
use crate::import::text::printable;
use crate::library::page::{self, Overview};
use crate::library::{Case, Filter, Verdict, collect, in_order, junit, junit_of};
use crate::model::{Choice, ModeChoice, Rig};

/// What else `scan` and `storage` take for files.
const FILES_REST: &str = ", folders (walked: every file in them that is an animation), globs (`'exports/**/*.fbx'`), \
                          or `-` for a list of paths on standard input";

/// The files a report over a library covers, how many at once, and how it is written: what `scan` and `storage`
/// share.
#[derive(Debug, Args)]
pub struct LibraryArgs {
    #[arg(required = true, help = files_help("The animation files", FILES_REST))]
    pub files: Vec<PathBuf>,
    /// In folders, scan only files matching this glob (by name, or by path below the folder when it has a `/`;
    /// case-insensitive; repeatable), e.g. `--include '*.fbx'`.
    #[arg(long, value_name = "GLOB")]
    pub include: Vec<String>,
    /// In folders, skip files matching this glob (as --include; repeatable).
    #[arg(long, value_name = "GLOB")]
    pub exclude: Vec<String>,
    /// Scan only the K-th of N stable parts of the files (by their path below the folder given, so N machines
    /// running the same command with K = 1..N split the library without talking; `cat` their JSON lines for the
    /// whole report).
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<(usize, usize)>,
    /// Files scanned at once (default: one per core); reports still come in the files' sorted order.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
    /// Report progress on standard error even when it is not a terminal (a line per file; on a terminal a bar is
    /// always shown).
    #[arg(long)]
    pub progress: bool,
    #[arg(long, value_enum, default_value_t)]
    pub format: ScanFormat,
    /// Report a folder named that holds no animation file as empty and go on, instead of failing with exit 2 (a job
    /// pointed at the wrong folder fails unless this is given).
    #[arg(long)]
    pub allow_empty: bool,
}

#[derive(Debug, Args)]
pub struct ScanArgs {
    #[command(flatten)]
    pub library: LibraryArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Samples per second, on top of every key time.
    #[arg(long, value_name = "HZ", default_value_t = ScanOptions::default().rate, value_parser = parse_rate)]
    pub rate: f64,
    /// Exit with status 1 when a bone is stretched and shears by more than DEGREES (without a value: any stretched
    /// bone).
    #[arg(long, value_name = "DEGREES", num_args = 0..=1, default_missing_value = "0", value_parser = parse_angle, alias = "fail-on-stretch")]
    pub fail_above: Option<f64>,
    /// Instead of the stretched bones, compare two evaluations of every bone: the largest difference in position
    /// (model units) and orientation (degrees) and when each happens. Each side is `declared` (the file's modes)
    /// or a mode id, e.g. `declared,full` (the file as its DCC meant it, against a glTF/TRS engine).
    #[arg(
        long,
        value_name = "A,B",
        value_parser = parse_comparison,
        conflicts_with_all = ["inherit", "inherit_bone", "fail_above"]
    )]
    pub compare_inherit: Option<[ModeChoice; 2]>,
    /// Explain each stretched bone: the bone whose scale shears it most and the fix that moves the skin least
    /// (`bonescope explain` has the whole story); a line per bone in the table, `explained` in the JSON.
    #[arg(long, conflicts_with = "compare_inherit")]
    pub explain: bool,
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
}

/// `bonescope storage`: each clip's stretch-quaternion storage: the bones that need a stretch channel, bytes as plain
/// TRS and with it, and the error of rebuilding the matrices with and without it.
#[derive(Debug, Args)]
pub struct StorageArgs {
    #[command(flatten)]
    pub library: LibraryArgs,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Frames per second, on top of every key time.
    #[arg(long, value_name = "HZ", default_value_t = StorageOptions::default().rate, value_parser = parse_rate)]
    pub rate: f64,
    /// How far along each bone's axes the error is measured, in the bone's local units.
    #[arg(long, value_name = "DISTANCE", default_value_t = StorageOptions::default().probe_distance)]
    pub probe_distance: f64,
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
}

/// How `scan` reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ScanFormat {
    /// Aligned columns for people; flagged bones marked.
    #[default]
    Table,
    /// One JSON array of every file's report, at the end.
    Json,
    /// One JSON object per line and file, written as soon as that file is done (a huge library streams; a crash
    /// loses nothing already written).
    Jsonl,
    /// JUnit XML for CI test reporters: a suite per file, a case per clip, a failure per stretched bone, an error
    /// per file that does not load (the stretch scan only).
    Junit,
    /// One self-contained HTML page: a sortable row per clip with a picture of its worst moment (the stretch scan
    /// only; `report --format html` makes the same page from a library's JSON lines).
    Html,
}

/// One clip of one file, as `bonescope storage` reports it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AnimationStorage {
    /// `null` for a file without animations, whose rest pose is measured instead.
    pub animation: Option<AnimationInfo>,
    pub inherit: String,
    pub rate: f64,
    #[serde(flatten)]
    pub report: StorageReport,
}

pub type FileStorage = FileReport<AnimationStorage>;

pub fn run(args: &ScanArgs) -> anyhow::Result<ExitCode> {
    let options = ScanOptions { rate: args.rate, tolerances: args.tolerances.tolerances()? };
    if let Some(sides) = args.compare_inherit {
        if args.eval.layers != LayerArgs::default() {
            anyhow::bail!("--compare-inherit compares the clips as authored: it takes no layer options");
        }
        return run_comparison(args, sides);
    }
    let report = |path: &Path| scan_file(path, args, &options);
    let (files, _) = report_files(&inputs(&args.library)?, &args.library, report, &render_animation, &junit)?;
    if args.library.format == ScanFormat::Html {
        super::print_out(page::html(&Overview::new(&files, args.fail_above), PAGE_TITLE))?;
    }
    Ok(verdict(&files, args.fail_above))
}

/// The title of the HTML page of a scan.
pub(super) const PAGE_TITLE: &str = "bonescope: shear in the library";

/// The exit code of a stretch scan ([`Verdict`]).
pub(super) fn verdict(files: &[FileScan], fail_above: Option<f64>) -> ExitCode {
    ExitCode::from(Verdict::of(files, fail_above).exit_status())
}

/// Refuses `--format html` for a scan other than the stretch scan (`what`): the page shows stretched bones.
fn only_stretch_pages(args: &LibraryArgs, what: &str) -> anyhow::Result<()> {
    match args.format {
        ScanFormat::Html => anyhow::bail!("--format html draws the stretch scan; {what} has tables, JSON and JUnit"),
        _ => Ok(()),
    }
}

/// The files the arguments name ([`crate::library::collect`]); what could not be read on the way is reported on
/// standard error, and the scan goes on. A folder named that gives no file is an error unless `--allow-empty`
/// (checked before `--shard` splits the files: a shard may rightly get none).
fn inputs(args: &LibraryArgs) -> anyhow::Result<Vec<PathBuf>> {
    let filter = Filter::new(&args.include, &args.exclude).map_err(anyhow::Error::msg)?;
    let inputs = collect(&args.files, &filter, &mut std::io::stdin().lock());
    for problem in &inputs.problems {
        eprintln!("warning: {}", printable(&format!("{}: {}", problem.path.display(), problem.message)));
    }
    if !(args.allow_empty || inputs.empty_folders.is_empty()) {
        let folders: Vec<String> = inputs.empty_folders.iter().map(|f| f.display().to_string()).collect();
        anyhow::bail!("no animation files under {}", folders.join(", "));
    }
    Ok(match args.shard {
        Some((part, parts)) => inputs.shard(part, parts),
        None => inputs.paths(),
    })
}

/// `K/N` with `1 ≤ K ≤ N`.
fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let parts = text.split_once('/').and_then(|(k, n)| Some((k.trim().parse().ok()?, n.trim().parse().ok()?)));
    match parts {
        Some((k, n)) if (1..=n).contains(&k) => Ok((k, n)),
        _ => Err(format!("expected K/N with 1 ≤ K ≤ N, e.g. 2/8, got `{text}`")),
    }
}

/// `storage` as JUnit: each clip passes with its storage report as output.
fn junit_storage(files: &[FileStorage]) -> String {
    junit_of(files, |file, clip| Case {
        name: AnimationInfo::describe(clip.animation.as_ref()),
        failures: Vec::new(),
        output: Some(render_storage(file, clip)),
    })
}

/// How a kind of report is written as JUnit XML.
type JunitOf<'a, T> = &'a dyn Fn(&[FileReport<T>]) -> String;

/// How one clip of a kind of report is written as a table, given its file's name.
type TableOf<'a, T> = &'a dyn Fn(&str, &T) -> String;

/// Reports every file of `paths` as `report` makes it, in `format`: JSON lines as each file is done, the other
/// formats at the end (tables per file by `animation`, JUnit by `junit` where the report has one); every file's
/// error also on standard error as it happens. The reports, and whether all files loaded.
fn report_files<T: serde::Serialize + Send>(
    paths: &[PathBuf],
    args: &LibraryArgs,
    report: impl Fn(&Path) -> FileReport<T> + Sync,
    animation: TableOf<T>,
    junit: JunitOf<T>,
) -> anyhow::Result<(Vec<FileReport<T>>, bool)> {
    let format = args.format;
    // Ctrl-C stops starting files; what is done is still written (a second handler, in tests, is refused: fine).
    let _ = ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::Relaxed));
    let mut progress = StderrProgress::new(paths.len(), args.progress);
    let mut files = Vec::with_capacity(paths.len());
    let mut out = std::io::stdout().lock();
    let mut written = Ok(());
    let jobs = args.jobs.map_or_else(|| std::thread::available_parallelism().map_or(1, usize::from), usize::from);
    let done = |path: &Path, file: FileReport<T>| {
        progress.file_done(path);
        if let Some(error) = &file.error {
            progress.println(&format!("error: {}", printable(error)));
        }
        if format == ScanFormat::Jsonl && written.is_ok() {
            written = serde_json::to_string(&file).map_err(anyhow::Error::from).and_then(|line| {
                writeln!(out, "{line}")?;
                Ok(out.flush()?)
            });
        }
        files.push(file);
    };
    let count = in_order(paths, jobs, report, done, &INTERRUPTED);
    progress.finish();
    written?;
    match format {
        ScanFormat::Json => super::print_json(&files)?,
        ScanFormat::Table => write!(out, "{}", render_files(&files, animation))?,
        ScanFormat::Junit => writeln!(out, "{}", junit(&files))?,
        // The stretch scan writes its page itself; the others have none ([`only_stretch_pages`]).
        ScanFormat::Jsonl | ScanFormat::Html => {}
    }
    if count < paths.len() {
        anyhow::bail!("interrupted: {count} of {} files scanned (their reports are above)", paths.len());
    }
    let loaded = files.iter().all(|f| f.error.is_none());
    Ok((files, loaded))
}

/// Set by Ctrl-C: no more files are started.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// StderrProgress on standard error: a bar (files done of total, files per second, time left, the current file) when it
/// is a terminal; with `--progress` elsewhere (CI logs), a line per file; nothing otherwise.
struct StderrProgress {
    bar: Option<indicatif::ProgressBar>,
    lines: bool,
    total: usize,
    done: usize,
}

impl StderrProgress {
    fn new(total: usize, forced: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let bar = terminal.then(|| {
            let style =
                indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} files  {per_sec}  ETA {eta}  {wide_msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            indicatif::ProgressBar::new(total as u64).with_style(style)
        });
        StderrProgress { bar, lines: forced && !terminal, total, done: 0 }
    }

    fn file_done(&mut self, path: &Path) {
        self.done += 1;
        match &self.bar {
            Some(bar) => {
                bar.set_message(shown(path));
                bar.inc(1);
            }
            None if self.lines => {
                eprintln!("[{}/{}] {}", self.done, self.total, shown(path));
            }
            None => {}
        }
    }

    /// A line on standard error that does not garble the bar.
    fn println(&self, line: &str) {
        match &self.bar {
            Some(bar) => bar.println(line),
            None => eprintln!("{line}"),
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// 0 when every file loaded, 2 when one did not.
fn loaded_code(all_loaded: bool) -> ExitCode {
    if all_loaded { ExitCode::SUCCESS } else { ExitCode::from(2) }
}

fn scan_file(path: &std::path::Path, args: &ScanArgs, options: &ScanOptions) -> FileScan {
    let file = shown(path);
    // Ctrl+C stops the library between files (`pool`): a file begun is scanned whole.
    let never = AtomicBool::new(false);
    let scanned = Loaded::read(path, &args.eval).and_then(|loaded| {
        let scanned = |evaluation: &Evaluation| scan_clip(evaluation, options, args.explain, &never);
        loaded.each_clip(|evaluation| scanned(evaluation).expect("never cancelled"))
    });
    FileReport::new(file, scanned)
}

/// A file loaded with what is evaluated of it, and the clips `--anim` picks.
struct Loaded {
    rig: Rig,
    setup: Setup,
    /// Positions in `rig.clips`; `None` for the rest pose of a file without animations.
    clips: Vec<Option<usize>>,
}

impl Loaded {
    fn read(path: &Path, eval: &EvalArgs) -> anyhow::Result<Loaded> {
        let rig = import::load(path)?;
        let (setup, clips) = (eval.setup(&rig)?, eval.clips(&rig)?);
        Ok(Loaded { rig, setup, clips })
    }

    /// `f` of each clip's evaluation.
    fn each_clip<T>(&self, mut f: impl FnMut(&Evaluation) -> T) -> anyhow::Result<Vec<T>> {
        let setups = self.clips.iter().map(|&clip| Setup { clip, ..self.setup.clone() });
        setups.map(|setup| Ok(f(&evaluation(&self.rig, &setup)?))).collect()
    }
}

/// `bonescope storage`.
pub fn run_storage(args: &StorageArgs) -> anyhow::Result<ExitCode> {
    only_stretch_pages(&args.library, "storage")?;
    if !(args.probe_distance > 0.0 && args.probe_distance.is_finite()) {
        anyhow::bail!("--probe-distance must be a positive number, got {}", args.probe_distance);
    }
    let (rate, tolerances) = (args.rate, args.tolerances.tolerances()?);
    let storage = StorageOptions { rate, tolerances, probe_distance: args.probe_distance };
    let measure = |path: &Path| {
        let file = shown(path);
        let measured = Loaded::read(path, &args.eval).and_then(|loaded| {
            let inherit = loaded.setup.modes.label();
            loaded.each_clip(|evaluation| AnimationStorage {
                animation: evaluation.clip.map(AnimationInfo::of),
                inherit: inherit.to_owned(),
                rate: storage.rate,
                report: storage_report(evaluation, &storage),
            })
        });
        FileStorage::new(file, measured)
    };
    let (_, loaded) = report_files(&inputs(&args.library)?, &args.library, measure, &render_storage, &junit_storage)?;
    Ok(loaded_code(loaded))
}

fn render_storage(file: &str, a: &AnimationStorage) -> String {
    let r = &a.report;
    let what = AnimationInfo::describe(a.animation.as_ref());
    let mut out = format!("{file}  {what}  {} frames × {} bones, inherit: {}\n", r.frames, r.bones, a.inherit);
    let marked: Vec<String> =
        r.marked.iter().map(|m| format!("{} ({}/{} frames)", m.name, m.stretched_frames, r.frames)).collect();
    let marked = if marked.is_empty() { "none".to_owned() } else { marked.join(", ") };
    out.push_str(&format!("  marked (stretch channel): {marked}\n"));
    let extra = r.bytes_with_stretch - r.bytes_trs;
    let percent = if r.bytes_trs > 0 { 100.0 * extra as f64 / r.bytes_trs as f64 } else { 0.0 };
    out.push_str(&format!(
        "  bytes: plain TRS {}, with stretch channel {} (+{extra}, +{percent:.2} %)\n",
        r.bytes_trs, r.bytes_with_stretch
    ));
    let mut table = Table::new(&[("error, model units", false), ("max", true), ("mean", true)]);
    for (label, runtime) in [("seed recomposition", &r.reconstruction), ("TRS only (stretch dropped)", &r.trs_only)] {
        error_rows(&mut table, label, runtime, r.probe_distance);
    }
    out.push_str(&table.to_string());
    out.push('\n');
    out
}

fn error_rows(table: &mut Table, label: &str, runtime: &RuntimeError, probe_distance: f64) {
    let row = |what: String, max: f64, mean: f64| vec![what, format!("{max:.3e}"), format!("{mean:.3e}")];
    let axes = runtime.bone_axes;
    table.row(row(format!("{label}, bone axes at {probe_distance}"), axes.max, axes.mean));
    if let Some(vertices) = runtime.vertices {
        table.row(row(format!("{label}, skinned vertices"), vertices.max, vertices.mean));
    }
}

/// `--compare-inherit`: each file's clips [`diff_files`]-compared with themselves under the two sides' modes.
fn run_comparison(args: &ScanArgs, sides: [ModeChoice; 2]) -> anyhow::Result<ExitCode> {
    only_stretch_pages(&args.library, "--compare-inherit")?;
    let compare = |path: &Path| FileReport::new(shown(path), compare_animations(path, args, sides));
    let [a, b] = sides.map(|side| side.id());
    let render = |file: &str, diff: &AnimationDiff| {
        format!("{file}  inherit: {a} against {b}\n{}\n", super::diff::render_animation(diff))
    };
    // As JUnit: it judges nothing, so each clip passes with its table as output.
    let junit = |files: &[FileReport<AnimationDiff>]| {
        junit_of(files, |file, diff| Case {
            name: diff.a.clone(),
            failures: Vec::new(),
            output: Some(render(file, diff)),
        })
    };
    let (_, loaded) = report_files(&inputs(&args.library)?, &args.library, compare, &render, &junit)?;
    Ok(loaded_code(loaded))
}

fn compare_animations(path: &Path, args: &ScanArgs, sides: [ModeChoice; 2]) -> anyhow::Result<Vec<AnimationDiff>> {
    let rig = import::load(path)?;
    let clip = args.eval.anim.as_ref().map(|name| clip_index(&rig, "--anim", name)).transpose()?;
    let [a, b] = sides.map(|modes| FileSide::new(shown(path), &rig, modes, clip));
    let clips = if clip.is_some() { Clips::Chosen } else { Clips::ByName };
    Ok(diff_files(&a, &b, clips, &[], args.rate, Align::Clocks)?.animations)
}

/// The table form: per file its clips, or why it could not be loaded.
pub(super) fn render_files<T>(files: &[FileReport<T>], animation: TableOf<T>) -> String {
    let mut out = String::new();
    for file in files {
        if let Some(error) = &file.error {
            out.push_str(&format!("{}\n  cannot load: {error}\n\n", file.file));
            continue;
        }
        for a in &file.animations {
            out.push_str(&animation(&file.file, a));
        }
    }
    out
}

pub(super) fn render_animation(file: &str, scan: &AnimationScan) -> String {
    let what = AnimationInfo::describe(scan.animation.as_ref());
    let mut out = format!("{file}  {what}  {} samples, inherit: {}\n", scan.samples, scan.inherit);
    if scan.stretched.is_empty() {
        out.push_str("  no stretched bones\n");
    } else {
        let mut table = Table::new(&[
            ("stretched bone", false),
            ("worst shear°", true),
            ("at s", true),
            ("frame", true),
            ("worst stretch°", true),
            ("flagged", true),
            ("first s", true),
        ]);
        for bone in &scan.stretched {
            let s = &bone.summary;
            table.row(vec![
                bone.name.clone(),
                format!("{:.3}", s.worst_shear_deg),
                format!("{:.4}", s.worst_shear_time),
                frame_at(s.worst_shear_time, scan.animation.as_ref().map(|a| a.frame_rate)),
                format!("{:.3}", s.worst_stretch_deg),
                format!("{}/{}", s.flagged_samples, scan.samples),
                s.first_flagged_time.map_or_else(String::new, |t| format!("{t:.4}")),
            ]);
        }
        out.push_str(&table.to_string());
    }
    for (label, names) in
        [("non-uniform (aligned)", &scan.non_uniform), ("mirrored", &scan.mirrored), ("degenerate", &scan.degenerate)]
    {
        if !names.is_empty() {
            out.push_str(&format!("  {label}: {}\n", names.join(", ")));
        }
    }
    for explained in &scan.explained {
        out.push_str(&format!("  why: {}\n", explained.line));
    }
    out.push('\n');
    out
}
