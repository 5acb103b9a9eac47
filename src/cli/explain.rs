//! `bonescope explain`: whose scale shears a bone, and which fix costs least.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use super::layers::bone_index;
use super::options::{files_help, parse_rate};
use super::setup::evaluation;
use super::table::{Table, frame_at, shown};
use super::{EvalArgs, OutputFormat, ToleranceArgs};
use crate::analysis::report::AnimationInfo;
use crate::analysis::{ScanOptions, scan_analysis};
use crate::explain::{Change, Costs, Explanation, Fix, Measured, Question, Report, explain, is_other_mode};
use crate::import;
use crate::model::{At, InheritMode, Rig, Unit};

#[derive(Debug, Args)]
pub struct ExplainArgs {
    #[arg(help = files_help("The animation file", ""))]
    pub file: PathBuf,
    /// The bone to explain, by name or index (repeatable; default: every stretched bone, the worst first).
    #[arg(long, value_name = "NAME|INDEX")]
    pub bone: Vec<String>,
    /// Show the chain at this time, in seconds (default: where each bone shears most).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub time: Option<f64>,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Samples per second, on top of every key time.
    #[arg(long, value_name = "HZ", default_value_t = ScanOptions::default().rate, value_parser = parse_rate)]
    pub rate: f64,
    /// List every fix measured, also those that change nothing (the JSON always lists every one).
    #[arg(long)]
    pub all: bool,
    #[arg(long, value_enum, default_value_t)]
    pub format: OutputFormat,
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
}

pub fn run(args: &ExplainArgs) -> anyhow::Result<ExitCode> {
    let rig = import::load(&args.file)?;
    let setup = args.eval.setup(&rig)?;
    if let Some(time) = args.time.filter(|t| !t.is_finite()) {
        anyhow::bail!("--time must be a finite number of seconds, got {time}");
    }
    let bones = args.bone.iter().map(|name| bone_index(&rig, "--bone", name)).collect::<anyhow::Result<Vec<_>>>()?;
    let options = ScanOptions { rate: args.rate, tolerances: args.tolerances.tolerances()? };
    let evaluation = evaluation(&rig, &setup)?;
    let before = scan_analysis(&evaluation, &options);
    let asked = (!bones.is_empty()).then_some(bones.as_slice());
    let question = Question { bones: asked, at: args.time, costs: Costs::Every, scale: None };
    let explained = explain(&evaluation, &before, question, &options);
    let report = Report::new(shown(&args.file), &evaluation, args.rate, &explained);
    match args.format {
        OutputFormat::Json => super::print_json(&report)?,
        OutputFormat::Table => {
            let shown = Shown { all: args.all, min_shear_deg: options.tolerances.min_shear_deg };
            super::print_out(render_table(&report, &rig, evaluation.modes(), shown))?;
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Which fixes the table lists: every one, or those that change something (a shear tolerance apart).
#[derive(Clone, Copy)]
struct Shown {
    all: bool,
    min_shear_deg: f64,
}

fn render_table(report: &Report, rig: &Rig, modes: &[InheritMode], shown: Shown) -> String {
    let animation = AnimationInfo::describe(report.animation.as_ref());
    let mut out = format!("{}  {animation}  inherit: {}\n", report.file, report.inherit);
    let layers = report.layers.summary(rig, report.animation.as_ref().and_then(|a| rig.clips.get(a.index)));
    if !layers.is_empty() {
        out.push_str(&format!("  layers: {layers}\n"));
    }
    if report.bones.is_empty() {
        out.push_str("  no stretched bones: nothing to explain\n");
    }
    for explained in report.bones {
        out.push('\n');
        let rate = report.animation.as_ref().map(|a| a.frame_rate);
        out.push_str(&render_bone(explained, rig, modes, (report.unit, rate), shown));
    }
    out
}

/// One bone: both answers, the chain at the detailed time (with its frame at the clip's `rate`), the main causes over
/// the clip, the fixes, and what the declared modes on the chain are worth.
fn render_bone(
    explained: &Explanation,
    rig: &Rig,
    modes: &[InheritMode],
    (unit, rate): (Option<Unit>, Option<f64>),
    shown: Shown,
) -> String {
    let (causes, at) = (&explained.causes, &explained.causes.at);
    let mut out = format!("{}\n", explained.headline(unit));
    if causes.stretched_samples == 0 {
        return out;
    }
    for answer in explained.answers(unit) {
        out.push_str(&format!("  {answer}\n"));
    }
    out.push_str(&format!(
        "  shears {:.3}° at {}{}; flagged at {} of {} samples\n",
        at.shear_deg,
        At { time: at.time, rate },
        if at.stretched { "" } else { " (not flagged there)" },
        causes.stretched_samples,
        causes.samples
    ));
    let mut chain = Table::new(&[
        ("chain, root first", false),
        ("scale k", false),
        ("unequal", true),
        ("turn°", true),
        ("shear left°", true),
        ("causes°", true),
        ("", false),
    ]);
    let main = at.main_cause().map(|l| l.bone);
    for link in &at.chain {
        let k = link.scale;
        chain.row(vec![
            format!("  {}", link.name),
            format!("({:.4}, {:.4}, {:.4})", k.x, k.y, k.z),
            format!("{:.2} %", 100.0 * link.anisotropy),
            link.turn_deg.map_or_else(String::new, |t| format!("{t:.2}")),
            format!("{:.3}", link.shear_left_deg),
            format!("{:.3}", link.contribution_deg),
            if Some(link.bone) == main { "◀ main cause".to_owned() } else { String::new() },
        ]);
    }
    out.push_str(&chain.to_string());
    let names: Vec<&str> = at.sufficient.iter().map(|&b| rig.skeleton.bone(b).name.as_str()).collect();
    if !names.is_empty() {
        out.push_str(&format!(
            "  contributions need not add up (scales compound and cancel); uniform scale on {} alone removes it\n",
            names.join(" and ")
        ));
    }
    if !causes.spans.is_empty() {
        let spans: Vec<String> =
            causes.spans.iter().map(|s| format!("{} {:.4}–{:.4} s", s.name, s.from, s.to)).collect();
        out.push_str(&format!("  main cause over the clip: {}\n", spans.join(", ")));
    }
    // The modes of the file's own tool first (every mode for a format without a tool of its own), the others apart.
    let listed = explained.shown_fixes(shown.all, shown.min_shear_deg);
    let (other, first): (Vec<&Fix>, Vec<&Fix>) = listed.partition(|fix| is_other_mode(fix.change, rig.tool));
    out.push_str(&render_fixes("  fixes, best first", &first, (unit, rate)));
    if !other.is_empty() {
        out.push_str(&render_fixes("  other modes", &other, (unit, rate)));
    }
    match explained.fixes.len() - first.len() - other.len() {
        0 => {}
        1 => out.push_str("  1 fix that changes nothing is left out (--all lists it)\n"),
        n => out.push_str(&format!("  {n} fixes that change nothing are left out (--all lists them)\n")),
    }
    out.push_str(&render_modes(explained, rig, modes, unit));
    for note in &explained.notes {
        out.push_str(&format!("  note: {note}\n"));
    }
    out
}

/// The fixes' table, lengths in `unit`, times with their frames at `rate`.
fn render_fixes(title: &'static str, fixes: &[&Fix], (unit, rate): (Option<Unit>, Option<f64>)) -> String {
    let mut table = Table::new(&[
        (title, false),
        ("shear left°", true),
        ("removes", false),
        ("moves", true),
        ("% of rig", true),
        ("at s", true),
        ("frame", true),
        ("elsewhere", false),
    ]);
    for fix in fixes {
        let mut elsewhere = Vec::new();
        if !fix.cleared().is_empty() {
            elsewhere.push(format!("clears {}", fix.cleared().join(", ")));
        }
        if !fix.newly_flagged().is_empty() {
            elsewhere.push(format!("shears {}", fix.newly_flagged().join(", ")));
        }
        table.row(vec![
            format!("  {}", fix.label),
            format!("{:.3}", fix.shear_left_deg),
            if fix.removes { "yes" } else { "no" }.to_owned(),
            Unit::readable(unit, fix.cost.distance.max),
            format!("{:.4}", 100.0 * fix.cost.fraction),
            format!("{:.4}", fix.cost.distance.time),
            frame_at(fix.cost.distance.time, rate),
            elsewhere.join("; "),
        ]);
    }
    table.to_string()
}

/// The chain's bones whose mode is not `full`, and what treating each as `full` (an engine that ignores the flag)
/// would do: the mode matters where that shears or moves something.
fn render_modes(explained: &Explanation, rig: &Rig, modes: &[InheritMode], unit: Option<Unit>) -> String {
    let mut out = String::new();
    for fix in &explained.fixes {
        let Change::Mode { bone, mode: InheritMode::Full } = fix.change else {
            continue;
        };
        let moved = match fix.cost.measured {
            Measured::Skin => "skin moves",
            Measured::Bones => "bones move",
        };
        out.push_str(&format!(
            "  mode on the chain: {} is {}; as full, {} shears {:.3}° and the {moved} {}\n",
            rig.skeleton.bone(bone).name,
            modes[bone],
            explained.name,
            fix.shear_left_deg,
            Unit::readable(unit, fix.cost.distance.max),
        ));
    }
    out
}
