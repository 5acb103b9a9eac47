//! `bonescope scan`: whole clips of several files, the stretched bones of each.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use super::table::Table;
use super::{EvalArgs, Format, ToleranceArgs};
use crate::analysis::report::{AnimationInfo, AnimationScan, FileScan};
use crate::analysis::{ScanOptions, scan};
use crate::eval::Hierarchy;
use crate::import;

#[derive(Debug, Args)]
pub struct ScanArgs {
    /// The animation files (glTF .gltf/.glb, FBX, BVH; recognised by content).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// Samples per second, on top of every key time.
    #[arg(long, value_name = "HZ", default_value_t = ScanOptions::default().rate)]
    pub rate: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Exit with status 1 when any bone is stretched.
    #[arg(long)]
    pub fail_on_stretch: bool,
    #[command(flatten)]
    pub tolerances: ToleranceArgs,
}

pub fn run(args: &ScanArgs) -> anyhow::Result<ExitCode> {
    if !(args.rate >= 0.0 && args.rate.is_finite()) {
        anyhow::bail!("--rate must be a finite number ≥ 0, got {}", args.rate);
    }
    let options = ScanOptions { rate: args.rate, tolerances: args.tolerances.tolerances()? };
    let files: Vec<FileScan> = args.files.iter().map(|path| scan_file(path, &args.eval, &options)).collect();
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&files)?),
        Format::Table => print!("{}", render(&files)),
    }
    let failed = files.iter().any(|f| f.error.is_some());
    let stretched = files.iter().flat_map(|f| &f.animations).any(|a| !a.stretched.is_empty());
    for file in files.iter().filter(|f| f.error.is_some()) {
        eprintln!("error: {}", file.error.as_deref().unwrap_or_default());
    }
    Ok(if failed {
        ExitCode::from(2)
    } else if stretched && args.fail_on_stretch {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn scan_file(path: &std::path::Path, eval: &EvalArgs, options: &ScanOptions) -> FileScan {
    let file = path.display().to_string();
    match scan_animations(path, eval, options) {
        Ok(animations) => FileScan { file, error: None, animations },
        Err(error) => FileScan { file, error: Some(format!("{error:#}")), animations: Vec::new() },
    }
}

fn scan_animations(
    path: &std::path::Path,
    eval: &EvalArgs,
    options: &ScanOptions,
) -> anyhow::Result<Vec<AnimationScan>> {
    let rig = import::load(path)?;
    let modes = eval.modes(&rig)?;
    let hierarchy = Hierarchy::new(&rig.skeleton, &modes);
    let clips = match eval.anim {
        Some(_) => vec![eval.clip(&rig)?],
        None if rig.clips.is_empty() => vec![None],
        None => rig.clips.iter().map(Some).collect(),
    };
    Ok(clips
        .into_iter()
        .map(|clip| {
            let result = scan(&rig.skeleton, clip, &hierarchy, options, &|_, _| {});
            AnimationScan::new(&rig.skeleton, clip, eval.inherit_label(), options.rate, result)
        })
        .collect())
}

fn render(files: &[FileScan]) -> String {
    let mut out = String::new();
    for file in files {
        if let Some(error) = &file.error {
            out.push_str(&format!("{}\n  cannot load: {error}\n\n", file.file));
            continue;
        }
        for scan in &file.animations {
            out.push_str(&render_animation(&file.file, scan));
        }
    }
    out
}

fn render_animation(file: &str, scan: &AnimationScan) -> String {
    let what = AnimationInfo::describe(scan.animation.as_ref());
    let mut out = format!("{file}  {what}  {} samples, inherit: {}\n", scan.samples, scan.inherit);
    if scan.stretched.is_empty() {
        out.push_str("  no stretched bones\n");
    } else {
        let mut table = Table::new(&[
            ("stretched bone", false),
            ("worst shear°", true),
            ("at s", true),
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
    out.push('\n');
    out
}
