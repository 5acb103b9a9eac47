//! `bonescope inspect`: every bone's matrices, decomposition and findings at chosen times, or every bone's model
//! matrix at every frame as a pose dump (`--format dump`, `dump-csv`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, ValueEnum};

use super::options::files_help;
use super::setup::evaluation;
use super::table::{Table, shown, vector};
use super::{EvalArgs, ToleranceArgs};
use crate::analysis::report::{AnimationInfo, BoneReport, LayeredInspectReport, SampleReport};
use crate::eval::Evaluation;
use crate::export::DumpWriter;
use crate::import;
use crate::import::dump::{DumpHeader, Syntax};
use crate::model::{At, Choice, UpAxis};

/// What `inspect` writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum InspectFormat {
    /// Aligned columns for people; flagged bones marked.
    #[default]
    Table,
    /// One JSON document on standard output.
    Json,
    /// A pose dump (JSON, docs/pose-dump.md): every bone's model matrix at every frame (or at each --time), as a
    /// runtime's dump would hold them; bonescope reads it back like any file.
    Dump,
    /// The same pose dump as CSV.
    DumpCsv,
}

#[derive(Debug, Args)]
pub struct InspectArgs {
    #[arg(help = files_help("The animation file", ""))]
    pub file: PathBuf,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// A time in seconds to evaluate (repeatable; default 0, for a dump every frame and key of the clip). Outside
    /// the clip the first or last key holds.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub time: Vec<f64>,
    #[arg(long, value_enum, default_value_t)]
    pub format: InspectFormat,
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
}

pub fn run(args: &InspectArgs) -> anyhow::Result<ExitCode> {
    let rig = import::load(&args.file)?;
    let setup = args.eval.setup(&rig)?;
    let tolerances = args.tolerances.tolerances()?;
    if let Some(bad) = args.time.iter().find(|t| !t.is_finite()) {
        anyhow::bail!("--time must be a finite number of seconds, got {bad}");
    }
    let evaluation = evaluation(&rig, &setup)?;
    let dump = match args.format {
        InspectFormat::Dump => Some(Syntax::Json),
        InspectFormat::DumpCsv => Some(Syntax::Csv),
        InspectFormat::Table | InspectFormat::Json => None,
    };
    if let Some(syntax) = dump {
        let source = format!("bonescope {} (inherit: {})", env!("CARGO_PKG_VERSION"), setup.modes.label());
        write_dump(&evaluation, &dump_times(&evaluation, &args.time), syntax, source)?;
        return Ok(ExitCode::SUCCESS);
    }
    let times = if args.time.is_empty() { vec![0.0] } else { args.time.clone() };
    let modes = evaluation.modes();
    let mut evaluator = evaluation.evaluator();
    let samples = times
        .iter()
        .map(|&time| {
            let pose = evaluator.evaluate(time);
            SampleReport { time, bones: BoneReport::all(&rig.skeleton, modes, pose, &tolerances) }
        })
        .collect();
    let summary = setup.layers.summary(&rig, evaluation.clip);
    let report = LayeredInspectReport::new(shown(&args.file), &evaluation, setup.modes.label().to_owned(), samples);
    match args.format {
        InspectFormat::Json => super::print_json(&report)?,
        _ => super::print_out(render_table(&report, &summary))?,
    }
    Ok(ExitCode::SUCCESS)
}

/// The times a dump holds: the ones asked for, sorted, else every frame and key of the clip at its frame rate.
fn dump_times(evaluation: &Evaluation, asked: &[f64]) -> Vec<f64> {
    if asked.is_empty() {
        return evaluation.times(evaluation.clip.map_or(0.0, |clip| clip.frame_rate()));
    }
    let mut times = asked.to_vec();
    times.sort_by(f64::total_cmp);
    times.dedup();
    times
}

/// Writes `evaluation` at `times` as a pose dump to standard output: world matrices, column-major, in the rig's
/// unit and bonescope's Y-up space.
fn write_dump(evaluation: &Evaluation, times: &[f64], syntax: Syntax, source: String) -> anyhow::Result<()> {
    use std::io::Write;
    let unit = evaluation.unit().or(evaluation.rig.unit);
    let clip = evaluation.clip.and_then(|clip| clip.name.clone());
    let header = DumpHeader { unit, up: Some(UpAxis::Y), clip, source: Some(source), ..DumpHeader::default() };
    let out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut writer = DumpWriter::new(out, syntax, header, evaluation.skeleton())?;
    let mut evaluator = evaluation.evaluator();
    for &time in times {
        writer.frame(time, &evaluator.evaluate(time).model.model)?;
    }
    writer.finish()?.flush()?;
    Ok(())
}

fn render_table(layered: &LayeredInspectReport, layers_summary: &str) -> String {
    let report = &layered.report;
    let animation = AnimationInfo::describe(report.animation.as_ref());
    let mut out = format!("{}  {}  inherit: {}\n", report.file, animation, report.inherit);
    for note in &report.notes {
        out.push_str(&format!("  note: {note}\n"));
    }
    if !layers_summary.is_empty() {
        out.push_str(&format!("  layers: {layers_summary}\n"));
    }
    for m in &layered.bind_mismatches {
        out.push_str(&format!("  warning: {}: the skin is broken there\n", m.says()));
    }
    let rate = report.animation.as_ref().map(|a| a.frame_rate);
    for sample in &report.samples {
        out.push_str(&format!(
            "\nt = {}   (model space; * = stretched: scale along axes that shear)\n",
            At { time: sample.time, rate }
        ));
        let mut table = Table::new(&[
            ("", false),
            ("#", true),
            ("bone", false),
            ("parent", false),
            ("inherit", false),
            ("translation", false),
            ("scale k", false),
            ("stretch°", true),
            ("shear°", true),
            ("findings", false),
        ]);
        for bone in &sample.bones {
            let parent = bone.parent.map_or_else(|| "-".to_owned(), |p| sample.bones[p].name.clone());
            table.row(vec![
                if bone.stretched { "*" } else { "" }.to_owned(),
                bone.index.to_string(),
                bone.name.clone(),
                parent,
                bone.inherit.id().to_owned(),
                vector(&bone.model.translation),
                vector(&bone.model.scale),
                format!("{:.3}", bone.assessment.stretch_deg),
                format!("{:.3}", bone.shear_deg),
                findings_text(bone),
            ]);
        }
        out.push_str(&table.to_string());
    }
    out
}

fn findings_text(bone: &BoneReport) -> String {
    let f = bone.assessment.findings;
    let words = [
        (f.stretched, "stretched"),
        (f.non_uniform, "non-uniform"),
        (f.mirrored, "mirrored"),
        (f.degenerate, "degenerate"),
    ];
    words.iter().filter(|(on, _)| *on).map(|(_, w)| *w).collect::<Vec<_>>().join(", ")
}
