//! `bonescope bake`: any scale inheritance baked into a plain glTF binary or a UsdSkel stage, with a report of how
//! exact it is.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use super::options::{Distance, choice, files_help, parse_distance};
use super::setup::evaluation;
use super::table::{Table, mesh_differences};
use super::{EvalArgs, OutputFormat};
use crate::bake::{self, BakeReport, Engine, Plan, Strategy, Written};
use crate::eval::Setup;
use crate::import;
use crate::model::{At, Choice, Unit};

#[derive(Debug, Args)]
pub struct BakeArgs {
    #[arg(help = files_help("The animation file", "; without one, the built-in demo rig"))]
    pub file: Option<PathBuf>,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Where to write, by its extension: a glTF binary `.glb`, or a UsdSkel stage `.usda` (text), `.usdc` (binary) or
    /// `.usdz` (package) of one clip (written whole or not at all).
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// The runtime the file is for: its strategy (trs for Unreal, exact elsewhere) and the rotation interpolation
    /// its keys must survive (slerp, nlerp, or both for `generic`).
    #[arg(long = "for", value_name = "ENGINE", value_parser = choice::<Engine>(), default_value = Engine::default().id())]
    pub engine: Engine,
    /// exact: a helper node `<bone>.stretch` above each bone that needs its stretch rotation; trs: one TRS node per
    /// bone, the closest to what it needs (for runtimes that cannot shear). Default: the --for engine's.
    #[arg(long, value_parser = choice::<Strategy>())]
    pub strategy: Option<Strategy>,
    /// Between keys the result stays within this fraction of the rig's size of the source (0 keeps every sample).
    #[arg(long, value_name = "FRACTION", default_value_t = bake::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Exit with status 1 when any probe point or vertex is farther than this from the source: a distance in model
    /// units (metres), or a percentage of the rig's size (`0.01%`).
    #[arg(long, value_name = "D", value_parser = parse_distance, alias = "max-error")]
    pub fail_above: Option<Distance>,
    #[arg(long, value_enum, default_value_t)]
    pub format: OutputFormat,
    /// The source's unit where its file states none (BVH): m, cm, mm, in, ft, cmu, or its length in metres.
    /// Without it, the unit its figure stands a person's height in, said in the report; the bake is in metres.
    #[arg(long, value_name = "UNIT")]
    pub unit: Option<Unit>,
}

pub fn run(args: &BakeArgs) -> anyhow::Result<ExitCode> {
    let rig = match &args.file {
        Some(path) => import::load(path)?,
        None => import::demo_rig(),
    };
    let (rig, assumed) = bake::in_metres(rig, args.unit).map_err(|why| anyhow::anyhow!("--unit: {why}"))?;
    // glTF is in metres: a source in another unit is measured in them.
    let setup = Setup { unit: Some(Unit::METRE), ..args.eval.setup(&rig)? };
    let source = evaluation(&rig, &setup)?;
    let only = args.eval.anim.is_some().then_some(source.clip).flatten();
    let plan = Plan { engine: args.engine, strategy: args.strategy, tolerance: args.tolerance };
    let Written { mut report, bytes } = bake::bake_file(&source, &source_name(args), only, &plan, &args.out)?;
    report.notes.extend(assumed.map(|note| format!("{note} (--unit to choose)")));
    match args.format {
        OutputFormat::Json => super::print_json(&report)?,
        OutputFormat::Table => super::print_out(render_table(args, &setup, &report, bytes))?,
    }
    let worst = report.worst();
    let over = args.fail_above.is_some_and(|limit| worst.max > limit.units(report.rig_size));
    Ok(if over { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// The source file's name, or the demo rig's.
fn source_name(args: &BakeArgs) -> String {
    args.file.as_ref().map_or_else(|| "the demo rig".to_owned(), |path| path.display().to_string())
}

fn render_table(args: &BakeArgs, setup: &Setup, report: &BakeReport, bytes: usize) -> String {
    let size = report.rig_size;
    let percent = |v: f64| format!("{:.6} %", 100.0 * v / size);
    let mut out = format!(
        "{} → {} ({bytes} bytes)  for: {}  strategy: {}  inherit: {}\n",
        source_name(args),
        args.out.display(),
        report.engine.id(),
        report.strategy.id(),
        setup.modes.label()
    );
    out.push_str(&format!("  {}\n", report.what_it_shows()));
    out.push_str(&format!(
        "  rig size {size:.6}; keys within {:.3e} ({} of the rig size)\n",
        report.tolerance, args.tolerance
    ));
    if report.strategy == Strategy::Exact {
        let helpers = if report.helpers.is_empty() { "none".to_owned() } else { report.helpers.join(", ") };
        out.push_str(&format!("  helper nodes for: {helpers}\n"));
    }
    for note in &report.notes {
        out.push_str(&format!("  note: {note}\n"));
    }
    for animation in &report.animations {
        out.push_str(&format!(
            "\nanimation `{}`: {} samples, {} keys; worst {:.3e} ({}) at {}\n",
            animation.name,
            animation.samples,
            animation.keys,
            animation.worst.max,
            percent(animation.worst.max),
            At { time: animation.worst.time, rate: animation.frame_rate }
        ));
        let mut bones = Table::new(&[
            ("bone", false),
            ("nodes", false),
            ("origin max", true),
            ("at s", true),
            ("probe max", true),
            ("of rig", true),
            ("at s", true),
        ]);
        for bone in &animation.bones {
            bones.row(vec![
                bone.name.clone(),
                format!("{:?}", bone.nodes).to_lowercase(),
                format!("{:.3e}", bone.origin.max),
                format!("{:.4}", bone.origin.time),
                format!("{:.3e}", bone.probe.max),
                percent(bone.probe.max),
                format!("{:.4}", bone.probe.time),
            ]);
        }
        out.push_str(&bones.to_string());
        if !animation.meshes.is_empty() {
            out.push_str(&mesh_differences(&animation.meshes, report.rig_size).to_string());
        }
        for unmatched in &animation.unmatched {
            out.push_str(&format!("  warning: {unmatched}\n"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_in_units_or_percent() {
        assert_eq!(parse_distance("0.5"), Ok(Distance::Units(0.5)));
        assert_eq!(parse_distance("0.01%"), Ok(Distance::Percent(0.01)));
        assert_eq!(parse_distance("2 %").map(|d| d.units(3.0)), Ok(0.06));
        assert!(parse_distance("-1").is_err() && parse_distance("far").is_err() && parse_distance("inf").is_err());
    }
}
