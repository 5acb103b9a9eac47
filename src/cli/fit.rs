//! `bonescope fit SOURCE DUMP`: which scale inheritance a runtime's pose dump implements, bone by bone
//! ([`crate::fit`]). Exit 0 when some mode fits every bone, 1 when none does (a CI gate for an engine's animation
//! code), 2 on bad input.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use super::options::{Distance, clip_index, files_help, parse_distance};
use super::setup::evaluation;
use super::table::{Table, shown};
use super::{LayerArgs, OutputFormat};
use crate::eval::Setup;
use crate::fit::{DEFAULT_TOLERANCE, Fit, fit};
use crate::import;
use crate::model::{Choice, ModeChoice, Unit};

#[derive(Debug, Args)]
pub struct FitArgs {
    #[arg(help = files_help("The source animation file", ""))]
    pub source: PathBuf,
    /// The runtime's pose dump of it (docs/pose-dump.md).
    pub dump: PathBuf,
    /// The source's animation, by name or index (default: the one named as the dump's, else the first).
    #[arg(long, value_name = "NAME|INDEX")]
    pub anim: Option<String>,
    /// The runtime techniques the source plays through (its modes are every mode in turn).
    #[command(flatten)]
    pub layers: LayerArgs,
    /// The largest distance a fitting mode may leave: model units, or a percentage of the rig's size (default
    /// 0.01%).
    #[arg(long, value_name = "DISTANCE", value_parser = parse_distance)]
    pub tolerance: Option<Distance>,
    #[arg(long, value_enum, default_value_t)]
    pub format: OutputFormat,
}

pub fn run(args: &FitArgs) -> anyhow::Result<ExitCode> {
    let source = import::load(&args.source)?;
    let dump = import::load(&args.dump)?;
    let named = dump.clips.first().and_then(|c| c.name.as_deref()).and_then(|name| source.find_clip(name));
    let clip = match (&args.anim, named) {
        (Some(name), _) => Some(clip_index(&source, "--anim", name)?),
        (None, Some(clip)) => source.clips.iter().position(|c| std::ptr::eq(c, clip)),
        (None, None) => Setup::declared(&source).clip,
    };
    let setup = Setup { clip, layers: args.layers.layers(&source)?, ..Setup::default() };
    let source_evaluation = evaluation(&source, &setup)?;
    let tolerance = |rig_size: f64| args.tolerance.map_or(DEFAULT_TOLERANCE * rig_size, |d| d.units(rig_size));
    let found = fit(&source_evaluation, &dump, tolerance)?;
    match args.format {
        OutputFormat::Json => super::print_json(&found)?,
        OutputFormat::Table => super::print_out(render(&found, &shown(&args.source), &shown(&args.dump), dump.unit))?,
    }
    Ok(if found.fits.is_empty() { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// The fit for people: the verdict first, then each bone where the mode matters.
fn render(fit: &Fit, source: &str, dump: &str, unit: Option<Unit>) -> String {
    let length = |l: f64| Unit::readable(unit, l);
    let mut out = format!(
        "{dump} against {source}: {} times, {} bones paired; tolerance {} ({:.3} % of the rig's size {})\n",
        fit.times,
        fit.bones.len(),
        length(fit.tolerance),
        100.0 * fit.tolerance / fit.rig_size,
        length(fit.rig_size),
    );
    let mattering: Vec<_> = fit.bones.iter().filter(|b| !b.any).collect();
    match fit.fits.first() {
        _ if mattering.is_empty() => out.push_str(&format!(
            "every mode fits every bone: nothing in the source scales where the modes differ ({} bones: any)\n",
            fit.bones.len()
        )),
        Some(&first) => {
            let first = if first == ModeChoice::Declared { fit.fits.get(1).copied().unwrap_or(first) } else { first };
            let others: Vec<&str> = fit.fits.iter().filter(|&&c| c != first).map(|c| c.id()).collect();
            out.push_str(&format!(
                "the dump is `{first}` on all {} bones ({} where the mode matters): {}\n",
                fit.bones.len(),
                mattering.len(),
                first.description()
            ));
            if !others.is_empty() {
                out.push_str(&format!("  as are: {}\n", others.join(", ")));
            }
        }
        None => out.push_str("no mode fits every bone\n"),
    }
    if fit.fits.is_empty() || fit.fits.len() > 1 {
        let mut table = Table::new(&[("bone", false), ("fits", false), ("closest", false), ("off by", true)]);
        for bone in &fit.bones {
            let fits: Vec<&str> = bone.fits.iter().map(|c| c.id()).collect();
            let fits = if bone.any {
                "any".to_owned()
            } else if fits.is_empty() {
                "none".to_owned()
            } else {
                fits.join(", ")
            };
            table.row(vec![bone.name.clone(), fits, bone.closest.id().to_owned(), length(bone.distance.max)]);
        }
        out.push_str(&table.to_string());
    }
    if let Some(miss) = &fit.miss {
        out.push_str(&format!(
            "first miss: `{}` at t = {} s, closest `{}` off by {}: {} (shear {:.3}° in the dump, {:.3}° under `{}`)\n",
            miss.bone,
            miss.time,
            miss.closest,
            length(miss.distance),
            miss.residual.describe(),
            miss.dump_shear_deg,
            miss.closest_shear_deg,
            miss.closest,
        ));
    }
    for (side, names) in [("source", &fit.only_source), ("dump", &fit.only_dump)] {
        if !names.is_empty() {
            out.push_str(&format!("  only in the {side}: {}\n", names.join(", ")));
        }
    }
    out
}
