//! What a report draws of a clip without its file: the figure seen from the front at its worst moment, each bone
//! with its shear there, and each stretched bone's shear over the clip. `scan` records it beside its findings, so
//! a page made from the JSON lines alone shows where a character shears.

use serde::{Deserialize, Serialize};

use super::{Assessment, ClipScan, Tolerances};
use crate::eval::Evaluation;

/// How many evenly spaced times of a clip a stretched bone's shear curve holds: enough for a sparkline's shape.
pub const CURVE_POINTS: usize = 48;

/// The steps across the figure's larger side that a bone's origin is placed in: a picture a few hundred pixels wide
/// needs no more, and small integers keep a library's report small.
pub const STEPS: i32 = 1000;

/// Shears are kept in hundredths of a degree: the precision of the figures a report prints.
pub const SHEAR_STEP_DEG: f64 = 0.01;

/// One clip's figure at its worst moment and its stretched bones' shear over the clip.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sketch {
    /// The time drawn, seconds on the file's clock: where the worst bone shears most.
    pub time: f64,
    /// The figure's extent seen from the front at that time, in the rig's units: `[min x, min y, max x, max y]` of
    /// model space, x to the right and y up.
    pub frame: [f64; 4],
    /// The figure's bones at that time, parents first: the place of its parent in this list (−1 for a root of the
    /// figure), its origin in [`STEPS`] across the frame's larger side from the frame's lower left corner (x, y), and
    /// its shear where it is stretched there (else 0), in steps of [`SHEAR_STEP_DEG`].
    pub bones: Vec<[i32; 4]>,
    /// The place in `bones` of the worst bone.
    pub worst: usize,
    /// Per stretched bone, in the scan's order (worst first): its shear, in steps of [`SHEAR_STEP_DEG`], at
    /// [`CURVE_POINTS`] evenly spaced times from the clip's start to its end.
    pub curves: Vec<Vec<u32>>,
}

impl Sketch {
    /// `evaluation`'s clip as `scan` found it with `tolerances`; `None` where no bone of it is stretched.
    pub fn of(evaluation: &Evaluation, scan: &ClipScan, tolerances: &Tolerances) -> Option<Self> {
        let stretched = scan.stretched_worst_first();
        let worst = stretched.first()?;
        let time = worst.worst_shear_time;
        let skeleton = evaluation.skeleton();
        let figure = skeleton.figure();
        let drawn: Vec<usize> = (0..skeleton.len()).filter(|&b| figure[b]).collect();
        let mut place = vec![None; skeleton.len()];
        drawn.iter().enumerate().for_each(|(i, &b)| place[b] = Some(i));
        let model = evaluation.pose_at(time).model.model;
        let origins: Vec<[f64; 2]> = drawn.iter().map(|&b| [model[b].w_axis.x, model[b].w_axis.y]).collect();
        let frame = extent(&origins);
        let side = (frame[2] - frame[0]).max(frame[3] - frame[1]);
        let step = |v: f64, min: f64| if side > 0.0 { ((v - min) / side * f64::from(STEPS)).round() as i32 } else { 0 };
        let bones = drawn
            .iter()
            .zip(&origins)
            .map(|(&b, &[x, y])| {
                // The nearest ancestor of the figure: a plain node between two bones is not drawn.
                let parent = std::iter::successors(skeleton.parent(b), |&p| skeleton.parent(p)).find_map(|p| place[p]);
                let assessed = Assessment::of(&model[b], tolerances);
                let shear = if assessed.findings.stretched { shear_steps(assessed.shear_deg) } else { 0 };
                [parent.map_or(-1, |p| p as i32), step(x, frame[0]), step(y, frame[1]), shear as i32]
            })
            .collect();
        let curves = curves(evaluation, &stretched.iter().map(|b| b.index).collect::<Vec<_>>(), tolerances);
        Some(Sketch { time, frame, bones, worst: place[worst.index].unwrap_or(0), curves })
    }
}

/// `[min x, min y, max x, max y]` of `points` (all zero for none).
fn extent(points: &[[f64; 2]]) -> [f64; 4] {
    if points.is_empty() {
        return [0.0; 4];
    }
    let mut extent = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    for &[x, y] in points {
        extent = [extent[0].min(x), extent[1].min(y), extent[2].max(x), extent[3].max(y)];
    }
    extent
}

/// Each of `bones`' shear at [`CURVE_POINTS`] evenly spaced times over `evaluation`'s clip.
fn curves(evaluation: &Evaluation, bones: &[usize], tolerances: &Tolerances) -> Vec<Vec<u32>> {
    let span = evaluation.span();
    let mut curves = vec![Vec::with_capacity(CURVE_POINTS); bones.len()];
    for i in 0..CURVE_POINTS {
        let time = span.start + span.length() * i as f64 / (CURVE_POINTS - 1) as f64;
        let model = evaluation.pose_at(time).model.model;
        for (curve, &bone) in curves.iter_mut().zip(bones) {
            curve.push(shear_steps(Assessment::of(&model[bone], tolerances).shear_deg));
        }
    }
    curves
}

/// A shear in steps of [`SHEAR_STEP_DEG`] (0 for a degenerate matrix's undefined one).
fn shear_steps(shear_deg: f64) -> u32 {
    if shear_deg.is_finite() { (shear_deg / SHEAR_STEP_DEG).round().clamp(0.0, f64::from(u32::MAX)) as u32 } else { 0 }
}
