//! `bonescope export`: every mesh as evaluated at one time, in the file's own units and axes or in bonescope's
//! Y-up metres (what `inspect` shows), the OBJ's header saying which.

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};

use super::EvalArgs;
use super::options::{choice, files_help};
use super::setup::evaluation;
use crate::eval::{Setup, SkinningMethod};
use crate::export::{EvaluatedMesh, write_obj};
use crate::import::{self, Options, Space};
use crate::model::Choice;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ExportFormat {
    /// Wavefront OBJ: one group per mesh, triangles.
    #[default]
    Obj,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    #[arg(help = files_help("The animation file", ""))]
    pub file: PathBuf,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// The time in seconds to evaluate. Outside the clip the first or last key holds.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub time: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: ExportFormat,
    /// How meshes are skinned: as the file declares (FBX: linear, dual quaternion or a per-vertex blend), or one
    /// method everywhere.
    #[arg(long, value_parser = choice::<SkinningMethod>(), default_value = SkinningMethod::default().id())]
    pub skinning: SkinningMethod,
    /// Where to write.
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,
    /// The space the positions are written in: `file`, the file's own axes and units (to compare with the authoring
    /// tool's own export of the frame), or `y-up-metres`, bonescope's (what `inspect` and the app show).
    #[arg(long, value_enum, default_value_t)]
    pub space: ExportSpace,
}

/// The space `export` writes positions in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ExportSpace {
    #[default]
    File,
    YUpMetres,
}

impl ExportSpace {
    fn loaded_as(self) -> Space {
        match self {
            ExportSpace::File => Space::File,
            ExportSpace::YUpMetres => Space::YUpMetres,
        }
    }

    /// The header's line on the space, with the rig's unit as loaded.
    fn says(self, unit: Option<crate::model::Unit>) -> String {
        let unit =
            unit.map_or_else(|| "the file's numbers as they are (it states no unit)".to_owned(), |u| u.to_string());
        match self {
            ExportSpace::File => {
                format!("space: the file's own axes and units ({unit}); --space y-up-metres for bonescope's")
            }
            ExportSpace::YUpMetres => format!("space: Y up, {unit}, as inspect shows; --space file for the file's own"),
        }
    }
}

pub fn run(args: &ExportArgs) -> anyhow::Result<ExitCode> {
    if !args.time.is_finite() {
        bail!("--time must be a finite number of seconds, got {}", args.time);
    }
    let rig = import::load_with(&args.file, &Options { space: args.space.loaded_as() })?;
    if rig.meshes.is_empty() {
        bail!("{}: no meshes to export", args.file.display());
    }
    let setup = Setup { skinning: args.skinning, ..args.eval.setup(&rig)? };
    let evaluation = evaluation(&rig, &setup)?;
    let positions = evaluation.skin_all(&evaluation.pose_at(args.time));
    let clip = evaluation.clip;
    let meshes: Vec<EvaluatedMesh> = rig
        .meshes
        .iter()
        .zip(&positions)
        .map(|(mesh, positions)| EvaluatedMesh { name: &mesh.name, positions, indices: &mesh.indices })
        .collect();
    let animation = clip.map_or_else(|| "rest pose".to_owned(), |c| format!("animation {} `{}`", c.index, c.label()));
    let mut header = vec![
        format!("bonescope export of {}", args.file.display()),
        format!(
            "{animation} at t = {} s, inherit: {}, skinning: {}",
            args.time,
            setup.modes.label(),
            args.skinning.label()
        ),
    ];
    header.push(args.space.says(rig.unit));
    let layers = setup.layers.summary(&rig, clip);
    if !layers.is_empty() {
        header.push(format!("layers: {layers}"));
    }
    header.extend(rig.notes.iter().cloned());
    let file = std::fs::File::create(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut out = BufWriter::new(file);
    match args.format {
        ExportFormat::Obj => write_obj(&mut out, &header, &meshes),
    }
    .and_then(|()| out.flush())
    .with_context(|| format!("cannot write {}", args.out.display()))?;
    let vertices: usize = positions.iter().map(Vec::len).sum();
    super::print_out(format_args!("wrote {} meshes ({vertices} vertices) to {}\n", meshes.len(), args.out.display()))?;
    Ok(ExitCode::SUCCESS)
}
