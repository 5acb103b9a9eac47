//! `bonescope render`: the viewport (or the whole app window) as PNG, at one time or as a sequence, optionally
//! checked against reference pictures.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};

use super::EvalArgs;
use super::options::{choice, files_help};
use crate::app::{BonescopeApp, Chrome, Compared, Document, Ghost, Pane, Settings};
use crate::eval::SkinningMethod;
use crate::import;
use crate::model::Choice;
use crate::render::{Background, Difference, Renderer, pixel_difference};
use crate::view::{SceneOptions, ViewKind};

#[derive(Debug, Args)]
pub struct RenderArgs {
    #[arg(help = files_help("The animation file", "; without one, the built-in demo rig"))]
    pub file: Option<PathBuf>,
    #[command(flatten)]
    pub eval: EvalArgs,
    /// The time to render, in seconds (default 0).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, conflicts_with = "frames")]
    pub time: Option<f64>,
    /// A sequence: frames START to END inclusive, every STEP, at --rate frames per second.
    #[arg(long, value_name = "START:END:STEP", value_parser = parse_frames)]
    pub frames: Option<Frames>,
    /// Frames per second of --frames and of `{frame}`.
    #[arg(long, value_name = "FPS", default_value_t = 30.0)]
    pub rate: f64,
    /// persp, front, side or top.
    #[arg(long, default_value = "persp")]
    pub view: ViewKind,
    /// Picture size in pixels.
    #[arg(long, value_name = "WxH", default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Draw a second pose translucent over the first: under this mode, `declared` (each bone's own mode), or
    /// `unlayered` (the clip without the layers); `none`: no ghost (the demo rig has one).
    #[arg(long, value_name = "MODE|declared|unlayered|none", value_parser = parse_ghost)]
    pub ghost: Option<GhostArg>,
    /// Compare with a second file (an export, a bake): its pose is the ghost, its bones paired with this file's by
    /// name, as `bonescope diff` pairs them (`--ghost` then picks another ghost instead).
    #[arg(long, value_name = "FILE")]
    pub compare: Option<PathBuf>,
    /// Select a bone by name (repeatable): highlighted in the viewport, plotted and inspected with --ui.
    #[arg(long, value_name = "NAME")]
    pub select: Vec<String>,
    /// What to draw: `bones,axes,boxes` exactly those, or `+boxes,-grid` to change the defaults. Items: bones,
    /// axes, boxes, mesh, wireframe, bind-pose, helpers (cameras, lights and other nodes beside the figure), names,
    /// grid, legend.
    #[arg(long, value_name = "LIST", allow_hyphen_values = true, value_parser = SceneOptions::parse_list)]
    pub show: Option<SceneOptions>,
    /// How meshes are skinned: as the file declares (FBX: linear, dual quaternion or a per-vertex blend), or one
    /// method everywhere.
    #[arg(long, value_parser = choice::<SkinningMethod>(), default_value = SkinningMethod::default().id())]
    pub skinning: SkinningMethod,
    /// The 3D camera: yaw and pitch in degrees, distance in model units (default: frames the whole animation).
    #[arg(long, value_name = "YAW,PITCH,DISTANCE", allow_hyphen_values = true, value_parser = parse_camera)]
    pub camera: Option<[f64; 3]>,
    /// Render the whole app window (panels, plots, inspector), not only the viewport.
    #[arg(long)]
    pub ui: bool,
    #[arg(long, value_enum, default_value_t)]
    pub theme: Theme,
    /// Leave the viewport's background transparent (a PNG with alpha, for compositing; not with --ui).
    #[arg(long, conflicts_with = "ui")]
    pub transparent: bool,
    /// Where to write the PNG. `{frame}` becomes the frame number (four digits), `{time}` the time in seconds.
    #[arg(long, value_name = "PATH", required_unless_present = "reference")]
    pub out: Option<PathBuf>,
    /// Compare with this picture (same templates as --out): exit 1 when more than --threshold differs, and write
    /// a diff image (`NAME.diff.png`) beside --out, or beside the reference without --out.
    #[arg(long, value_name = "PATH")]
    pub reference: Option<PathBuf>,
    /// The largest share of differing pixels, in percent, that still passes --reference.
    #[arg(long, value_name = "PERCENT", default_value_t = 0.1, requires = "reference")]
    pub threshold: f64,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Theme {
    #[default]
    Dark,
    Light,
}

/// `--ghost`: off, or which ghost.
#[derive(Clone, Debug, PartialEq)]
pub struct GhostArg(Option<Ghost>);

/// `--frames START:END:STEP`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frames {
    pub start: i64,
    pub end: i64,
    pub step: i64,
}

impl Frames {
    fn numbers(self) -> impl Iterator<Item = i64> {
        (self.start..=self.end).step_by(self.step as usize)
    }
}

/// Sequences longer than this are surely a typo.
const MAX_RENDERED_FRAMES: i64 = 1_000_000;

fn parse_frames(s: &str) -> Result<Frames, String> {
    let parts: Vec<&str> = s.split(':').collect();
    let [start, end, step] = parts[..] else { return Err(format!("expected START:END:STEP, got `{s}`")) };
    let number = |p: &str| p.trim().parse::<i64>().map_err(|_| format!("`{p}` is not a whole frame number"));
    let frames = Frames { start: number(start)?, end: number(end)?, step: number(step)? };
    if frames.step < 1 || frames.end < frames.start {
        return Err(format!("expected START ≤ END and STEP ≥ 1, got `{s}`"));
    }
    if (frames.end - frames.start) / frames.step >= MAX_RENDERED_FRAMES {
        return Err(format!("more than {MAX_RENDERED_FRAMES} frames in `{s}`"));
    }
    Ok(frames)
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X', '×']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{s}`"))?;
    let side = |p: &str| p.trim().parse::<u32>().map_err(|_| format!("`{p}` is not a number of pixels"));
    Ok((side(w)?, side(h)?))
}

fn parse_ghost(s: &str) -> Result<GhostArg, String> {
    match s {
        "none" => Ok(GhostArg(None)),
        "unlayered" => Ok(GhostArg(Some(Ghost::Unlayered))),
        choice => choice
            .parse()
            .map(|choice| GhostArg(Some(Ghost::Modes(choice))))
            .map_err(|e| format!("{e}, `unlayered` or `none`")),
    }
}

fn parse_camera(s: &str) -> Result<[f64; 3], String> {
    let values: Result<Vec<f64>, _> = s.split(',').map(|p| p.trim().parse::<f64>()).collect();
    match values.as_deref() {
        Ok(&[yaw, pitch, distance]) if [yaw, pitch].iter().all(|v| v.is_finite()) && distance > 0.0 => {
            Ok([yaw, pitch, distance])
        }
        _ => Err(format!("expected YAW,PITCH,DISTANCE (degrees, degrees, a distance > 0), got `{s}`")),
    }
}

/// One picture of the sequence.
struct Shot {
    frame: i64,
    time: f64,
}

impl Shot {
    /// `{frame}` and `{time}` filled in.
    fn path(&self, template: &Path) -> PathBuf {
        let text = template.to_string_lossy();
        let filled =
            text.replace("{frame}", &format!("{:04}", self.frame)).replace("{time}", &format!("{:.3}", self.time));
        PathBuf::from(filled)
    }
}

pub fn run(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    if !(args.rate > 0.0 && args.rate.is_finite()) {
        bail!("--rate must be a positive number of frames per second, got {}", args.rate);
    }
    if args.threshold.is_nan() || args.threshold < 0.0 {
        bail!("--threshold must be a percentage ≥ 0, got {}", args.threshold);
    }
    let shots = shots(args)?;
    for template in [&args.out, &args.reference].into_iter().flatten() {
        if shots.len() > 1 && !is_template(template) {
            bail!("{} frames would all go to {}: put {{frame}} or {{time}} in it", shots.len(), template.display());
        }
    }
    let background = if args.transparent { Background::Transparent } else { Background::Viewport };
    let mut renderer = Renderer::new(app(args)?, args.size.0, args.size.1, background)?;
    // Pictures are written and compared on a second thread while the next one renders.
    std::thread::scope(|scope| {
        let (pictures, received) = std::sync::mpsc::sync_channel::<(&Shot, image::RgbaImage)>(2);
        let finisher = scope.spawn(move || {
            received
                .into_iter()
                .try_fold(true, |within, (shot, image)| finish(args, shot, &image).map(|ok| ok && within))
        });
        for shot in &shots {
            // A closed channel means the finisher stopped on an error, which its result carries.
            if pictures.send((shot, renderer.render(shot.time)?)).is_err() {
                break;
            }
        }
        drop(pictures);
        let within = finisher.join().map_err(|_| anyhow::anyhow!("the PNG writer stopped unexpectedly"))??;
        Ok(if within { ExitCode::SUCCESS } else { ExitCode::from(1) })
    })
}

/// Writes one picture and compares it with its reference; whether it is within the threshold.
fn finish(args: &RenderArgs, shot: &Shot, image: &image::RgbaImage) -> anyhow::Result<bool> {
    if let Some(out) = &args.out {
        let path = shot.path(out);
        image.save(&path).with_context(|| format!("cannot write {}", path.display()))?;
        super::print_out(format_args!("wrote {}\n", path.display()))?;
    }
    match &args.reference {
        Some(reference) => check(args, shot, image, &shot.path(reference)),
        None => Ok(true),
    }
}

fn is_template(path: &Path) -> bool {
    let text = path.to_string_lossy();
    text.contains("{frame}") || text.contains("{time}")
}

/// The times to render.
fn shots(args: &RenderArgs) -> anyhow::Result<Vec<Shot>> {
    if let Some(frames) = args.frames {
        return Ok(frames.numbers().map(|frame| Shot { frame, time: frame as f64 / args.rate }).collect());
    }
    let time = args.time.unwrap_or(0.0);
    if !time.is_finite() {
        bail!("--time must be a finite number of seconds, got {time}");
    }
    Ok(vec![Shot { frame: (time * args.rate).round() as i64, time }])
}

/// The app as the options set it up: document, modes, ghost, view, selection and what is drawn.
fn app(args: &RenderArgs) -> anyhow::Result<BonescopeApp> {
    let mut doc = match &args.file {
        Some(path) => Document::new(Some(path.clone()), import::load(path)?),
        None => Document::demo(),
    };
    let rig = doc.rig.clone();
    doc.set_setup(args.eval.setup(&rig)?)?;
    if let Some(path) = &args.compare {
        doc.compare_with(Compared::load(path, &doc.rig)?);
    }
    if let Some(GhostArg(ghost)) = &args.ghost {
        doc.ghost = *ghost;
    }
    let selection = args
        .select
        .iter()
        .map(|name| rig.skeleton.find(name).with_context(|| format!("--select: no bone named `{name}`")))
        .collect::<anyhow::Result<Vec<usize>>>()?;
    // With layers, the whole window shows the panel that describes them.
    let show_layers = !doc.layers().is_empty();
    let settings = Settings { dark: args.theme == Theme::Dark, ..Settings::default() };
    let mut settings = settings.showing(&Pane::LAYERS, show_layers);
    settings.scene = SceneOptions { skinning: args.skinning, ..args.show.unwrap_or_default() };
    settings.camera.view = args.view;
    if let Some([yaw, pitch, _]) = args.camera {
        (settings.camera.yaw, settings.camera.pitch) = (yaw.to_radians(), pitch.to_radians());
    }
    let mut app = BonescopeApp::new(settings, doc);
    if let Some([_, _, distance]) = args.camera {
        // Frame first (for the target), then take the asked distance.
        app.frame_now(f64::from(args.size.0) / f64::from(args.size.1.max(1)));
        app.settings.camera.distance = distance;
    }
    app.window.selection = selection;
    // A render shows what its options say, not the bone a file would open on.
    app.window.opening = false;
    app.window.chrome = if args.ui { Chrome::Window } else { Chrome::ViewportOnly };
    Ok(app)
}

/// Compares one picture with its reference, prints the measure, writes the diff image when it fails.
fn check(args: &RenderArgs, shot: &Shot, image: &image::RgbaImage, reference: &Path) -> anyhow::Result<bool> {
    let expected = image::open(reference)
        .with_context(|| format!("cannot read the reference picture {}", reference.display()))?
        .to_rgba8();
    let difference = pixel_difference(&expected, image);
    let within = difference.percent() <= args.threshold;
    super::print_out(format_args!("{}\n", summary(reference, &difference, args.threshold, within)))?;
    if !within && let Some(diff) = &difference.image {
        let path = diff_path(args.out.as_ref().map_or(reference.to_owned(), |out| shot.path(out)).as_path());
        diff.save(&path).with_context(|| format!("cannot write {}", path.display()))?;
        super::print_out(format_args!("wrote {}\n", path.display()))?;
    }
    Ok(within)
}

fn summary(reference: &Path, d: &Difference, threshold: f64, within: bool) -> String {
    let verdict = if within { "within" } else { "over" };
    let sizes = d
        .sizes
        .map_or_else(String::new, |([w, h], [rw, rh])| format!(" (sizes differ: reference {w}×{h}, render {rw}×{rh})"));
    format!(
        "{}: {:.4} % of pixels differ ({} of {}), {verdict} the threshold of {threshold} %{sizes}",
        reference.display(),
        d.percent(),
        d.differing,
        d.total
    )
}

/// `NAME.diff.png` beside `path`.
fn diff_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map_or_else(|| "render".into(), |s| s.to_string_lossy());
    path.with_file_name(format!("{stem}.diff.png"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::InheritMode;

    #[test]
    fn frame_ranges_parse_and_reject_nonsense() {
        assert_eq!(parse_frames("0:10:5"), Ok(Frames { start: 0, end: 10, step: 5 }));
        assert_eq!(parse_frames("0:10:5").unwrap().numbers().collect::<Vec<_>>(), [0, 5, 10]);
        assert_eq!(parse_frames("-2:1:2").unwrap().numbers().collect::<Vec<_>>(), [-2, 0]);
        for bad in ["0:10", "0:10:0", "5:1:1", "a:1:1", "0:99999999:1"] {
            assert!(parse_frames(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn sizes_cameras_and_ghosts_parse() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert!(parse_size("1280").is_err());
        assert_eq!(parse_camera("30,-10,4.5"), Ok([30.0, -10.0, 4.5]));
        assert!(parse_camera("30,10,0").is_err());
        assert_eq!(parse_ghost("none"), Ok(GhostArg(None)));
        assert_eq!(parse_ghost("unlayered"), Ok(GhostArg(Some(Ghost::Unlayered))));
        use crate::model::ModeChoice;
        assert_eq!(parse_ghost("declared"), Ok(GhostArg(Some(Ghost::Modes(ModeChoice::Declared)))));
        let compensate = ModeChoice::Mode(InheritMode::SegmentCompensate);
        assert_eq!(parse_ghost("segment-compensate"), Ok(GhostArg(Some(Ghost::Modes(compensate)))));
        assert!(parse_ghost("sideways").is_err());
    }

    #[test]
    fn templates_fill_frame_and_time() {
        let shot = Shot { frame: 7, time: 0.2333 };
        assert_eq!(shot.path(Path::new("out/f_{frame}_{time}.png")), PathBuf::from("out/f_0007_0.233.png"));
        assert_eq!(diff_path(Path::new("out/f_0007.png")), PathBuf::from("out/f_0007.diff.png"));
    }
}
