//! The machine-readable reports (`inspect --format json`, `scan --format json`), shared by the CLI and the app.

use glam::DMat4;
use serde::Serialize;

use super::{Assessment, ClipScan, Tolerances};
use crate::eval::Pose;
use crate::math::{AffineParts, decompose};
use crate::model::{Clip, InheritMode, Skeleton};

/// A matrix and its decomposition `T·F·R·U·K·Uᵀ`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Parts {
    /// Column-major.
    pub matrix: [f64; 16],
    pub translation: [f64; 3],
    /// `[x, y, z, w]`.
    pub rotation: [f64; 4],
    /// The stretch rotation `U`, `[x, y, z, w]`.
    pub stretch: [f64; 4],
    pub scale: [f64; 3],
    /// 1, or −1 for a mirroring matrix.
    pub sign: i32,
}

impl Parts {
    pub fn new(matrix: &DMat4, parts: &AffineParts) -> Self {
        Parts {
            matrix: matrix.to_cols_array(),
            translation: parts.translation.to_array(),
            rotation: parts.rotation.to_array(),
            stretch: parts.stretch.to_array(),
            scale: parts.scale.to_array(),
            sign: if parts.sign < 0.0 { -1 } else { 1 },
        }
    }
}

/// Which clip a report is about.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct AnimationInfo {
    pub index: usize,
    pub name: Option<String>,
    /// Where the clip starts on its file's clock, seconds ([`Clip::span`]).
    #[serde(default)]
    pub start: f64,
    /// How long it plays, seconds.
    pub duration: f64,
    /// Frames per second: the file's, or for glTF the rate its key times show ([`Clip::frame_rate`]).
    pub frame_rate: f64,
}

impl AnimationInfo {
    pub fn of(clip: &Clip) -> Self {
        AnimationInfo {
            index: clip.index,
            name: clip.name.clone(),
            start: clip.span().start,
            duration: clip.span().length(),
            frame_rate: clip.frame_rate(),
        }
    }

    /// `animation 0 `walk` (1.333 s)` (`(2.000 s from 0.0333 s)` for a clip that does not start at 0 on its file's
    /// clock), or the rest pose when there is no animation.
    pub fn describe(animation: Option<&AnimationInfo>) -> String {
        let Some(a) = animation else { return "rest pose (no animations)".to_owned() };
        let from = if a.start == 0.0 { String::new() } else { format!(" from {:.4} s", a.start) };
        match &a.name {
            Some(name) => format!("animation {} `{name}` ({:.3} s{from})", a.index, a.duration),
            None => format!("animation {} ({:.3} s{from})", a.index, a.duration),
        }
    }
}

/// One bone at one time. `stretched`, `shear_deg` and `mirrored` describe the model matrix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BoneReport {
    pub index: usize,
    pub node: usize,
    pub name: String,
    pub parent: Option<usize>,
    pub inherit: InheritMode,
    pub local: Parts,
    /// The model matrix in bonescope's space, its scale factors the authored ones (over the unit conversion above
    /// the bone, [`Skeleton::length_scales`]).
    pub model: Parts,
    pub stretched: bool,
    pub shear_deg: f64,
    pub mirrored: bool,
    /// Everything found about the model matrix (not part of the JSON: `stretched` and `mirrored` say it there).
    #[serde(skip)]
    pub assessment: Assessment,
}

impl BoneReport {
    /// Every bone of an evaluated pose.
    pub fn all(skeleton: &Skeleton, modes: &[InheritMode], pose: &Pose, tolerances: &Tolerances) -> Vec<BoneReport> {
        let assessments = Assessment::all(&pose.model.model, tolerances);
        let length_scales = skeleton.length_scales();
        skeleton
            .bones()
            .iter()
            .zip(assessments)
            .enumerate()
            .map(|(index, (bone, assessment))| {
                let local = pose.local[index].matrix();
                let model = pose.model.model[index];
                BoneReport {
                    index,
                    node: bone.node,
                    name: bone.name.clone(),
                    parent: bone.parent,
                    inherit: modes[index],
                    local: Parts::new(&local, &decompose(&local)),
                    model: Parts::new(&model, &assessment.parts.authored(length_scales[index])),
                    stretched: assessment.findings.stretched,
                    shear_deg: assessment.shear_deg,
                    mirrored: assessment.findings.mirrored,
                    assessment,
                }
            })
            .collect()
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleReport {
    pub time: f64,
    pub bones: Vec<BoneReport>,
}

/// `bonescope inspect --format json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InspectReport {
    pub file: String,
    /// What the importer says about the file (units and axes, how animation was read, what was skipped), and
    /// which joints the stored pose holds away from the bind pose.
    pub notes: Vec<String>,
    pub animation: Option<AnimationInfo>,
    /// The mode given for every bone, or `declared` when each bone keeps the file's.
    pub inherit: String,
    pub samples: Vec<SampleReport>,
}

/// One bone's whole-clip summary, with its name.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct BoneScanReport {
    pub name: String,
    #[serde(flatten)]
    pub summary: super::BoneSummary,
}

/// One clip of one file, scanned.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct AnimationScan {
    /// `null` for a file without animations, whose rest pose is scanned instead.
    pub animation: Option<AnimationInfo>,
    pub inherit: String,
    pub rate: f64,
    pub samples: usize,
    /// Bones stretched in at least one sample, worst shear first.
    pub stretched: Vec<BoneScanReport>,
    /// Bones with other findings in at least one sample.
    pub non_uniform: Vec<String>,
    pub mirrored: Vec<String>,
    pub degenerate: Vec<String>,
    /// With `scan --explain`: each stretched bone's main cause and best fix (`crate::explain`), worst first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub explained: Vec<ExplainedBone>,
    /// Where a bone is stretched: the figure at the worst moment and the stretched bones' shear over the clip, for
    /// a report to draw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sketch: Option<super::sketch::Sketch>,
}

/// A stretched bone's explanation in brief: whose squash shears it most, and the cheapest fix.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct ExplainedBone {
    pub name: String,
    /// The bone of its chain whose uniform scale would remove the most shear where it shears most.
    pub main_cause: Option<String>,
    /// Where no one bone's squash causes it: the fewest bones whose scales, made uniform together, remove it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub together: Vec<String>,
    /// The best fix, what it leaves, and how far it moves the skin (or, without a mesh, the bones' probe points):
    /// in the rig's units and as a fraction of its size.
    pub best_fix: Option<String>,
    pub fix_removes: Option<bool>,
    pub fix_cost: Option<f64>,
    pub fix_cost_fraction: Option<f64>,
    /// All of it in a line for people.
    pub line: String,
    /// The two answers, a line each: how to play it as authored in any engine, and how to remove the shear.
    #[serde(default)]
    pub answers: Vec<String>,
}

impl AnimationScan {
    pub fn new(skeleton: &Skeleton, clip: Option<&Clip>, inherit: String, rate: f64, scan: ClipScan) -> Self {
        let name = |i: usize| skeleton.bone(i).name.clone();
        let names_where = |count: fn(&super::BoneSummary) -> usize| {
            scan.bones.iter().filter(|b| count(b) > 0).map(|b| name(b.index)).collect::<Vec<_>>()
        };
        let non_uniform = names_where(|b| b.non_uniform_samples);
        let mirrored = names_where(|b| b.mirrored_samples);
        let degenerate = names_where(|b| b.degenerate_samples);
        let stretched = scan.stretched_worst_first();
        let stretched = stretched.into_iter().map(|b| BoneScanReport { name: name(b.index), summary: b.clone() });
        let stretched = stretched.collect();
        AnimationScan {
            animation: clip.map(AnimationInfo::of),
            inherit,
            rate,
            samples: scan.samples,
            stretched,
            non_uniform,
            mirrored,
            degenerate,
            explained: Vec::new(),
            sketch: None,
        }
    }
}

/// One file of `bonescope scan` (plain or `--compare-inherit`) or `bonescope storage`: a report per clip, or why the file
/// could not be loaded.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct FileReport<T> {
    pub file: String,
    pub error: Option<String>,
    pub animations: Vec<T>,
}

impl<T> FileReport<T> {
    /// The reports of `file`'s clips, or the error that stopped them (in its alternate form, which for an
    /// `anyhow::Error` lists the causes).
    pub fn new(file: String, animations: Result<Vec<T>, impl std::fmt::Display>) -> Self {
        match animations {
            Ok(animations) => FileReport { file, error: None, animations },
            Err(error) => FileReport { file, error: Some(format!("{error:#}")), animations: Vec::new() },
        }
    }
}

pub type FileScan = FileReport<AnimationScan>;

/// `bonescope inspect --format json`: the report, the layers every sample was evaluated through (the default: none)
/// and the skin joints whose bind matrices break the skin (joints only posed away from their bind are in the notes:
/// [`super::BindCheck`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LayeredInspectReport {
    #[serde(flatten)]
    pub report: InspectReport,
    pub layers: crate::eval::Layers,
    pub bind_mismatches: Vec<super::BindMismatch>,
}

impl LayeredInspectReport {
    /// The report `inspect` prints (and the app copies) of `file` (as named) evaluated as `evaluation` is, at the
    /// given samples; `inherit` says what the modes are (`declared`, a mode's id, or `mixed`).
    pub fn new(
        file: String,
        evaluation: &crate::eval::Evaluation,
        inherit: String,
        samples: Vec<SampleReport>,
    ) -> Self {
        let rig = evaluation.rig;
        let animation = evaluation.clip.map(AnimationInfo::of);
        let bind = super::check_bind(evaluation, &super::BindTolerance::default());
        let notes = rig.notes.iter().cloned().chain(bind.note()).collect();
        let report = InspectReport { file, notes, animation, inherit, samples };
        let layers = evaluation.layers().map(|stack| stack.layers().clone()).unwrap_or_default();
        LayeredInspectReport { report, layers, bind_mismatches: bind.broken }
    }
}
