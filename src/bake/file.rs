//! A bake as every face asks for one: the source read in metres, baked for an engine, written to the file named,
//! read back and measured. The command line and the Python module both call [`in_metres`] and [`bake_file`], so
//! what one accepts, writes and reports the other does too.

use std::path::{Path, PathBuf};

use super::{BakeReport, Engine, Output, Request, Strategy, bake_to, report, save};
use crate::eval::Evaluation;
use crate::import::{self, ImportError};
use crate::model::{Clip, Rig, Unit};

/// What a bake is asked for besides its source: the engine it is for, how (the engine's strategy where `None`), and
/// how close between keys, as a fraction of the rig's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    pub engine: Engine,
    pub strategy: Option<Strategy>,
    pub tolerance: f64,
}

/// Why a bake was not written.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    #[error("{}: bake writes a file named {} (got `{}`)", .0.display(), Output::EXTENSIONS, extension(.0))]
    Output(PathBuf),
    #[error("the tolerance must be a finite fraction ≥ 0, got {0}")]
    Tolerance(f64),
    #[error("{0}: no nodes to bake")]
    NoNodes(String),
    #[error("the baked file does not read back (a bug): {0}")]
    ReadBack(ImportError),
    #[error("{}: {why} (a bug)", .path.display())]
    Encode { path: PathBuf, why: String },
    /// The system's reason is said in the line, not chained: every face prints one line.
    #[error("cannot write {}: {why}", .path.display())]
    Write { path: PathBuf, why: std::io::Error },
}

/// "none", or the extension of `path` as written.
fn extension(path: &Path) -> String {
    path.extension().map_or_else(|| "no extension".to_owned(), |e| format!(".{}", e.to_string_lossy()))
}

/// `rig` in a unit, as a bake (in metres) needs: its file's, the one `given` (only where the file states none), else
/// the one its figure stands a person's height in, with a note saying so (a face adds how to choose another).
pub fn in_metres(rig: Rig, given: Option<Unit>) -> Result<(Rig, Option<String>), String> {
    let mut rig = rig.given_unit(given)?;
    if rig.unit.is_some() {
        return Ok((rig, None));
    }
    let size = Evaluation::declared(&rig, None).size(&[0.0]);
    let unit = Unit::likeliest_for_figure(size).unwrap_or(Unit::METRE);
    rig.unit = Some(unit);
    let tall = Unit::readable(Some(unit), size);
    let note = format!("the file states no unit: read in {unit}, where its figure stands {tall} across at rest");
    Ok((rig, Some(note)))
}

/// A bake written: its report, measured on the file as written and read back, and its size in bytes.
#[derive(Debug)]
pub struct Written {
    pub report: BakeReport,
    pub bytes: usize,
}

/// Bakes `source` (every clip of its rig, or `only`), named `name` in errors, as `plan` asks, and writes it whole to
/// `out` (or nothing), a file of the kind its extension names ([`Output::of`]): the output and the plan are checked
/// before any work. A USD stage has one timeline: it gets `only`, else the clip `source` plays, and the report says
/// which clips it leaves out.
pub fn bake_file(
    source: &Evaluation,
    name: &str,
    only: Option<&Clip>,
    plan: &Plan,
    out: &Path,
) -> Result<Written, BakeError> {
    let output = Output::of(out).ok_or_else(|| BakeError::Output(out.to_owned()))?;
    if !(plan.tolerance.is_finite() && plan.tolerance >= 0.0) {
        return Err(BakeError::Tolerance(plan.tolerance));
    }
    if source.skeleton().is_empty() {
        return Err(BakeError::NoNodes(name.to_owned()));
    }
    let strategy = plan.strategy.unwrap_or(plan.engine.strategy());
    let only = if output.one_clip() { only.or(source.clip) } else { only };
    let request = Request::of(source, only, strategy, plan.tolerance).for_engine(plan.engine);
    let baked = bake_to(&request, output).map_err(|why| BakeError::Encode { path: out.to_owned(), why })?;
    let read_back = import::load_bytes(out, &baked.bytes).map_err(BakeError::ReadBack)?;
    let mut report = report(&request, &baked, &read_back);
    report.notes.extend(left_out(source.rig, only, output));
    save(out, &baked.bytes).map_err(|why| BakeError::Write { path: out.to_owned(), why })?;
    Ok(Written { report, bytes: baked.bytes.len() })
}

/// A note of the clips a file of `output`'s kind leaves out of `rig`'s, having baked `baked` alone.
fn left_out(rig: &Rig, baked: Option<&Clip>, output: Output) -> Option<String> {
    let baked = baked.filter(|_| output.one_clip() && rig.clips.len() > 1)?;
    let others: Vec<String> = rig.clips.iter().filter(|c| c.index != baked.index).map(|c| c.label()).collect();
    Some(format!(
        "a USD stage plays one animation: baked `{}`, not {} (--anim names another)",
        baked.label(),
        others.iter().map(|o| format!("`{o}`")).collect::<Vec<_>>().join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bake_is_refused_before_any_work_where_its_output_or_plan_cannot_be() {
        let rig = import::demo_rig();
        let source = Evaluation::declared(&rig, rig.clips.first());
        let dir = tempfile::tempdir().unwrap();
        let plan = Plan { engine: Engine::default(), strategy: None, tolerance: 1e-4 };
        let fbx = dir.path().join("demo.fbx");
        let refused = bake_file(&source, "demo", None, &plan, &fbx).unwrap_err();
        assert_eq!(
            refused.to_string(),
            format!("{}: bake writes a file named `.glb`, `.usda`, `.usdc` or `.usdz` (got `.fbx`)", fbx.display())
        );
        assert!(!fbx.exists(), "nothing written");
        let bare = dir.path().join("demo");
        assert!(
            bake_file(&source, "demo", None, &plan, &bare).unwrap_err().to_string().ends_with("(got `no extension`)")
        );
        let plan = Plan { tolerance: f64::NAN, ..plan };
        let refused = bake_file(&source, "demo", None, &plan, &dir.path().join("demo.GLB")).unwrap_err();
        assert_eq!(refused.to_string(), "the tolerance must be a finite fraction ≥ 0, got NaN");
    }

    #[test]
    fn a_bake_written_reads_back_as_its_report_says() {
        let rig = import::demo_rig();
        let source = Evaluation::declared(&rig, rig.clips.first());
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("demo.glb");
        let plan = Plan { engine: Engine::default(), strategy: None, tolerance: 1e-4 };
        let written = bake_file(&source, "demo", None, &plan, &out).unwrap();
        assert_eq!(std::fs::metadata(&out).unwrap().len() as usize, written.bytes);
        assert!(written.report.worst().max <= written.report.tolerance, "{:?}", written.report.worst());
    }
}
