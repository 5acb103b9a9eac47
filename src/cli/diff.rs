//! `bonescope diff`: two evaluations compared over time, bone by bone and vertex by vertex.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use super::OutputFormat;
use super::options::{Distance, choice, files_help, parse_assignment, parse_distance, parse_rate};
use super::table::{Table, mesh_differences, shown};
use crate::diff::{
    Align, AnimationDiff, Clips, FileDiff, FileSide, chosen_clips, diff_files, match_clips, standing_apart,
};
use crate::eval::layers::RotationInterpolation;
use crate::import;
use crate::model::{At, Choice, ModeChoice, Rig, Unit, UpAxis, frames};

#[derive(Debug, Args)]
pub struct DiffArgs {
    #[arg(help = files_help("The first file", ""))]
    pub a: PathBuf,
    /// The second file.
    pub b: PathBuf,
    /// The first file's animation (name or index); without --anim-a/--anim-b every animation is compared with the
    /// other file's animation of the same name.
    #[arg(long, value_name = "NAME|INDEX")]
    pub anim_a: Option<String>,
    /// The second file's animation (name or index).
    #[arg(long, value_name = "NAME|INDEX")]
    pub anim_b: Option<String>,
    /// The first file's inheritance: `declared` (what its file says) or one mode for every bone.
    #[arg(long, value_name = "MODE", value_parser = choice::<ModeChoice>(), default_value = ModeChoice::Declared.id())]
    pub inherit_a: ModeChoice,
    /// The second file's inheritance.
    #[arg(long, value_name = "MODE", value_parser = choice::<ModeChoice>(), default_value = ModeChoice::Declared.id())]
    pub inherit_b: ModeChoice,
    /// Pair a bone of the first file with one of the second explicitly (repeatable); the rest pair by name, exactly,
    /// then ignoring case and namespace prefixes such as `mixamorig:` or `Armature|`.
    #[arg(long = "map", value_name = "A=B", value_parser = parse_assignment)]
    pub map: Vec<(String, String)>,
    /// The first file's unit where the file states none (BVH): m, cm, mm, in, ft, cmu (the CMU mocap database's
    /// 1/0.45 inch), or its length in metres. Lengths are compared in the first file's unit.
    #[arg(long, value_name = "UNIT")]
    pub unit_a: Option<Unit>,
    /// The second file's unit where the file states none; the second file's lengths are brought into the first's.
    #[arg(long, value_name = "UNIT")]
    pub unit_b: Option<Unit>,
    /// The axis the first file's skeleton stands along, where the file does not say (BVH) or says wrongly: `z` turns
    /// a Z-up file (Blender's, 3ds Max's) into bonescope's Y-up space.
    #[arg(long, value_name = "AXIS", value_parser = choice::<UpAxis>())]
    pub up_a: Option<UpAxis>,
    /// The axis the second file's skeleton stands along.
    #[arg(long, value_name = "AXIS", value_parser = choice::<UpAxis>())]
    pub up_b: Option<UpAxis>,
    /// How the second file's linear rotation keys are played: `slerp` as glTF says, `nlerp` as a runtime that
    /// keys each quaternion component as a curve of its own (Blender, Unity, Unreal) plays a bake.
    #[arg(long, value_parser = choice::<RotationInterpolation>(), value_name = "MODE", default_value = RotationInterpolation::default().id())]
    pub interp: RotationInterpolation,
    /// How the second file's clock meets the first's: `clocks` compares equal times of both files' own clocks (a
    /// time reads the same in every format), `start` plays the second clip from the first's start (one exporter
    /// starts each take at 0, another at its first frame), a number of seconds plays the second that much later.
    #[arg(long, value_name = "clocks|start|SECONDS", default_value = "clocks", allow_hyphen_values = true)]
    pub align: Align,
    /// Samples per second where both clips play, on top of both files' key times.
    #[arg(long, value_name = "HZ", default_value_t = crate::diff::DEFAULT_RATE, value_parser = parse_rate)]
    pub rate: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: OutputFormat,
    /// Exit with status 1 when a bone's origin or axis probe, or a vertex, differs by more than this: a distance in
    /// the first file's unit, or a percentage (`0.01%`) of the larger rig's size.
    #[arg(long, value_name = "DIST", value_parser = parse_distance, alias = "max-error")]
    pub fail_above: Option<Distance>,
}

pub fn run(args: &DiffArgs) -> anyhow::Result<ExitCode> {
    let stood = |rig: Rig, up: Option<UpAxis>| match up {
        Some(up) => rig.stood_up(up),
        None => rig,
    };
    let rig_a = stated_unit(stood(import::load(&args.a)?, args.up_a), args.unit_a, "--unit-a")?;
    let rig_b = stated_unit(stood(import::load(&args.b)?, args.up_b), args.unit_b, "--unit-b")?;
    let chosen = chosen(args, &rig_a, &rig_b)?;
    if let Some(note) = lying_down(&rig_a, &rig_b, chosen) {
        eprintln!("note: {note}");
    }
    let [clip_a, clip_b] = chosen.map_or([None, None], |[a, b]| [Some(a), Some(b)]);
    let a = FileSide::new(shown(&args.a), &rig_a, args.inherit_a, clip_a);
    let mut b = FileSide::new(shown(&args.b), &rig_b, args.inherit_b, clip_b);
    b.setup.layers.interpolation.rotation = args.interp;
    let clips = if chosen.is_some() { Clips::Chosen } else { Clips::ByName };
    let diff = diff_files(&a, &b, clips, &args.map, args.rate, args.align)?;
    match args.format {
        OutputFormat::Json => super::print_json(&diff)?,
        OutputFormat::Table => super::print_out(render_table(&diff, [args.unit_a.is_some(), args.unit_b.is_some()]))?,
    }
    if let Some(apart) = diff.animations.iter().find(|a| a.samples == 0) {
        anyhow::bail!("`{}` and `{}` never play at the same time: {}", apart.a, apart.b, never_together(apart));
    }
    let over = |a: &AnimationDiff| args.fail_above.is_some_and(|limit| a.worst.max > limit.units(a.rig_size));
    Ok(if diff.animations.iter().any(over) { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// Where two clips that never play at once lie, and how to meet them.
fn never_together(animation: &AnimationDiff) -> String {
    let (a, b) = (animation.span_a, animation.span_b);
    format!(
        "A from {:.4} to {:.4} s, B from {:.4} to {:.4} s on their own clocks (B played {:.4} s later); --align start \
         plays B from A's start",
        a.start, a.end, b.start, b.end, animation.delay_b
    )
}

/// The frame conventions found, one line for each (bones that share one listed together): what was taken out of the
/// probes, orientations and scales.
fn conventions(animation: &AnimationDiff) -> Vec<String> {
    let mut groups: Vec<(String, Vec<&str>)> = Vec::new();
    for bone in &animation.bones {
        let Some(c) = &bone.convention else { continue };
        let round = |x: f64| (x * 1000.0).round() / 1000.0 + 0.0;
        let (x, y, z) = (round(c.axis.x), round(c.axis.y), round(c.axis.z));
        let what = format!("turned {:.2}° about ({x}, {y}, {z})", c.turn_deg);
        match groups.iter_mut().find(|(w, _)| *w == what) {
            Some((_, bones)) => bones.push(&bone.name),
            None => groups.push((what, vec![&bone.name])),
        }
    }
    groups
        .into_iter()
        .map(|(what, bones)| {
            format!("frames of B {what} from A's (the files' conventions, taken out): {}", bones.join(", "))
        })
        .collect()
}

/// What to say of two clips' clocks: how far apart their starts are where nothing aligned them, or how B was moved.
fn clocks_note(animation: &AnimationDiff) -> Option<String> {
    let gap = animation.span_a.start - animation.span_b.start;
    let frames = |seconds: f64| match animation.frame_rate {
        Some(rate) => {
            let count = frames(seconds * rate);
            let noun = if count.trim_start_matches('-') == "1" { "frame" } else { "frames" };
            format!(" ({count} {noun} at {rate} fps)")
        }
        None => String::new(),
    };
    if animation.delay_b != 0.0 {
        let (d, when) = match animation.delay_b {
            d if d > 0.0 => (d, "later"),
            d => (-d, "earlier"),
        };
        return Some(format!("B played {d:.4} s{} {when} than its clock says, to meet A's", frames(d)));
    }
    (gap.abs() > 1e-6).then(|| {
        let (how, lead) = if gap > 0.0 { ("before", gap) } else { ("after", -gap) };
        format!(
            "B's clip starts {lead:.4} s{} {how} A's on its own clock; compared at equal times (--align start compares \
             them start to start)",
            frames(lead)
        )
    })
}

/// The clips `--anim-a` and `--anim-b` choose ([`chosen_clips`]), a clip a file lacks named with the file and the
/// option that asked for it.
fn chosen(args: &DiffArgs, a: &Rig, b: &Rig) -> anyhow::Result<Option<[usize; 2]>> {
    let names = [args.anim_a.as_deref(), args.anim_b.as_deref()];
    chosen_clips([a, b], names).map_err(|missing| {
        let file = shown(if missing.searched == 0 { &args.a } else { &args.b });
        let [option, other] = [["--anim-a", "--anim-b"][missing.named_by], ["--anim-b", "--anim-a"][missing.named_by]];
        match missing.searched == missing.named_by {
            true => anyhow::anyhow!("{file}: {option}: {}", missing.why),
            false => anyhow::anyhow!(
                "{file}: no animation named as {option} chose in the other file ({}); choose this file's with {other}",
                missing.why
            ),
        }
    })
}

/// `rig` in `unit` (given as `option`), which only a rig whose file states no unit may be given.
fn stated_unit(rig: Rig, unit: Option<Unit>, option: &str) -> anyhow::Result<Rig> {
    rig.given_unit(unit).map_err(|why| anyhow::anyhow!("{option}: {why}"))
}

/// What to give where one file's skeleton lies down beside the other's.
fn lying_down(a: &Rig, b: &Rig, chosen: Option<[usize; 2]>) -> Option<String> {
    // As they play: the clips chosen, else the first two that pair by name (or each file's only one).
    let paired = || match_clips(&a.clips, &b.clips).0.first().map(|&(i, j)| [i, j]);
    let one_each = (a.clips.len() == 1 && b.clips.len() == 1).then_some([0, 0]);
    let [clip_a, clip_b] = chosen.or_else(paired).or(one_each).map_or([None, None], |[i, j]| [Some(i), Some(j)]);
    let [up_a, up_b] = standing_apart((a, clip_a), (b, clip_b))?;
    let (side, option, up) = if up_a == UpAxis::Y { ("B", "--up-b", up_b) } else { ("A", "--up-a", up_a) };
    Some(format!(
        "A's skeleton stands along {}, B's along {}: every distance measures the turn; if {side} is {}-up, give \
         {option} {}",
        up_a.id().to_uppercase(),
        up_b.id().to_uppercase(),
        up.id().to_uppercase(),
        up.id()
    ))
}

/// The table of `diff`, saying which units were `given` (`--unit-a`, `--unit-b`).
fn render_table(diff: &FileDiff, given: [bool; 2]) -> String {
    let [unit_a, unit_b] = [(diff.unit_a, given[0]), (diff.unit_b, given[1])].map(|(unit, given)| match unit {
        Some(unit) if given => format!("{unit} (given; the file states none)"),
        Some(unit) => unit.to_string(),
        None => "not stated (numbers taken as they are)".to_owned(),
    });
    let played = |interp: RotationInterpolation| match interp {
        RotationInterpolation::Slerp => String::new(),
        other => format!("  rotations: {}", other.id()),
    };
    let (played_a, played_b) = (played(diff.interp_a), played(diff.interp_b));
    let mut out = format!("A: {}  inherit: {}  unit: {unit_a}{played_a}\n", diff.a, diff.inherit_a);
    out.push_str(&format!("B: {}  inherit: {}  unit: {unit_b}{played_b}\n", diff.b, diff.inherit_b));
    if let (Some(a), Some(b)) = (diff.unit_a, diff.unit_b)
        && a != b
    {
        out.push_str(&format!("  B's lengths scaled by {} into A's {a}\n", b.per(a)));
    }
    for clip in &diff.clips_only_a {
        out.push_str(&format!("  animation only in A: {clip}\n"));
    }
    for clip in &diff.clips_only_b {
        out.push_str(&format!("  animation only in B: {clip}\n"));
    }
    for animation in &diff.animations {
        out.push('\n');
        out.push_str(&render_animation(animation));
    }
    out
}

/// One pair of animations: the worst distance, every bone's differences, the meshes', what had no partner.
pub(super) fn render_animation(animation: &AnimationDiff) -> String {
    let mut out = String::new();
    let percent = |v: f64| format!("{:.4} %", 100.0 * v / animation.rig_size);
    out.push_str(&format!(
        "`{}` against `{}`: {} samples, rig size {:.4}; worst distance {:.3e} ({}) at {}\n",
        animation.a,
        animation.b,
        animation.samples,
        animation.rig_size,
        animation.worst.max,
        percent(animation.worst.max),
        At { time: animation.worst.time, rate: animation.frame_rate }
    ));
    if let Some(note) = clocks_note(animation) {
        out.push_str(&format!("  {note}\n"));
    }
    let mut bones = Table::new(&[
        ("bone", false),
        ("position", true),
        ("at s", true),
        ("probe", true),
        ("at s", true),
        ("orientation°", true),
        ("at s", true),
        ("scale ratio", true),
        ("at s", true),
        ("stretch°", true),
        ("at s", true),
    ]);
    for bone in &animation.bones {
        let name = match &bone.name_b {
            Some(other) => format!("{} = {other}", bone.name),
            None => bone.name.clone(),
        };
        bones.row(vec![
            name,
            format!("{:.3e}", bone.position.max),
            format!("{:.4}", bone.position.time),
            format!("{:.3e}", bone.probe.max),
            format!("{:.4}", bone.probe.time),
            format!("{:.4}", bone.orientation_deg.max),
            format!("{:.4}", bone.orientation_deg.time),
            format!("{:.6}", bone.scale_ratio.max),
            format!("{:.4}", bone.scale_ratio.time),
            format!("{:.4}", bone.stretch_deg.max),
            format!("{:.4}", bone.stretch_deg.time),
        ]);
    }
    out.push_str(&bones.to_string());
    if !animation.meshes.is_empty() {
        out.push_str(&mesh_differences(&animation.meshes, animation.rig_size).to_string());
    }
    for line in conventions(animation) {
        out.push_str(&format!("  {line}\n"));
    }
    if !animation.only_a.is_empty() {
        out.push_str(&format!("  bones only in A: {}\n", animation.only_a.join(", ")));
    }
    if !animation.only_b.is_empty() {
        out.push_str(&format!("  bones only in B: {}\n", animation.only_b.join(", ")));
    }
    if animation.helpers > 0 {
        out.push_str(&format!("  {} bake helper nodes (`*.stretch`) left out\n", animation.helpers));
    }
    for (side, nodes) in [("A", &animation.skinned_a), ("B", &animation.skinned_b)] {
        if !nodes.is_empty() {
            out.push_str(&format!(
                "  skinned meshes' nodes of {side} left out (their skins follow the joints): {}\n",
                nodes.join(", ")
            ));
        }
    }
    for (side, nodes) in [("A", &animation.conversion_a), ("B", &animation.conversion_b)] {
        if !nodes.is_empty() {
            out.push_str(&format!(
                "  conversion nodes of {side} left out (they only state axes and unit): {}\n",
                nodes.join(", ")
            ));
        }
    }
    out
}
