//! An evaluation sampled at given times into flat arrays, every bone at every time: what `inspect` prints per bone,
//! for the whole clip at once and in a layout other tools read without converting (the Python module hands these
//! buffers to numpy as they are).

use glam::DMat4;

use super::findings::{Assessment, Tolerances};
use crate::eval::{Evaluation, over_runs};

/// Every bone of an evaluation at every one of `times`, time-major: element `[t][b]` of an array of `n` numbers per
/// bone starts at `(t · bones + b) · n`. Matrices are row by row (`m[row][column]`, the translation in the last
/// column), quaternions `[x, y, z, w]`. The model parts are `inspect`'s: the scale factors the authored ones (the
/// unit conversion above the bone divided out).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sampled {
    pub times: Vec<f64>,
    pub bones: usize,
    /// 16 per bone.
    pub local: Vec<f64>,
    /// 16 per bone.
    pub model: Vec<f64>,
    /// The model matrix's parts, `T·F·R·U·K·Uᵀ`: 3 per bone.
    pub translation: Vec<f64>,
    /// `R`: 4 per bone.
    pub rotation: Vec<f64>,
    /// The stretch rotation `U`: 4 per bone.
    pub stretch: Vec<f64>,
    /// `K`: 3 per bone.
    pub scale: Vec<f64>,
    /// `F`: 1 or −1.
    pub sign: Vec<f64>,
    /// The largest deviation from 90° between two columns of the model matrix, in degrees.
    pub shear_deg: Vec<f64>,
    /// The angle of `U` with scale factors within the anisotropy tolerance of each other merged, in degrees.
    pub stretch_deg: Vec<f64>,
    /// The verdict: stretched under `tolerances`.
    pub stretched: Vec<bool>,
}

impl Sampled {
    /// Room for `bones` bones at `count` times.
    fn with_capacity(bones: usize, count: usize) -> Self {
        let room = |n: usize| Vec::with_capacity(bones * count * n);
        let flags = Vec::with_capacity(bones * count);
        Sampled {
            times: Vec::with_capacity(count),
            bones,
            local: room(16),
            model: room(16),
            translation: room(3),
            rotation: room(4),
            stretch: room(4),
            scale: room(3),
            sign: room(1),
            shear_deg: room(1),
            stretch_deg: room(1),
            stretched: flags,
        }
    }

    /// One bone at one time, after the ones before it.
    fn push(&mut self, local: &DMat4, model: &DMat4, assessment: &Assessment, length_scale: f64) {
        let parts = assessment.parts.authored(length_scale);
        self.local.extend(local.transpose().to_cols_array());
        self.model.extend(model.transpose().to_cols_array());
        self.translation.extend(parts.translation.to_array());
        self.rotation.extend(parts.rotation.to_array());
        self.stretch.extend(parts.stretch.to_array());
        self.scale.extend(parts.scale.to_array());
        self.sign.push(parts.sign);
        self.shear_deg.push(assessment.shear_deg);
        self.stretch_deg.push(assessment.stretch_deg);
        self.stretched.push(assessment.findings.stretched);
    }

    /// `later`'s times after these.
    fn append(&mut self, mut later: Sampled) {
        self.times.append(&mut later.times);
        self.local.append(&mut later.local);
        self.model.append(&mut later.model);
        self.translation.append(&mut later.translation);
        self.rotation.append(&mut later.rotation);
        self.stretch.append(&mut later.stretch);
        self.scale.append(&mut later.scale);
        self.sign.append(&mut later.sign);
        self.shear_deg.append(&mut later.shear_deg);
        self.stretch_deg.append(&mut later.stretch_deg);
        self.stretched.append(&mut later.stretched);
    }
}

/// `evaluation` at each of `times` (in the order given), every bone, judged with `tolerances`; runs of consecutive
/// times on every core.
pub fn sample(evaluation: &Evaluation, times: &[f64], tolerances: &Tolerances) -> Sampled {
    let bones = evaluation.skeleton().len();
    let length_scales = evaluation.skeleton().length_scales();
    let runs = over_runs(times, |run| {
        let mut sampled = Sampled::with_capacity(bones, run.len());
        let mut evaluator = evaluation.evaluator();
        for &time in run {
            let pose = evaluator.evaluate(time);
            let assessments = Assessment::all(&pose.model.model, tolerances);
            for (b, assessment) in assessments.iter().enumerate() {
                sampled.push(&pose.local[b].matrix(), &pose.model.model[b], assessment, length_scales[b]);
            }
            sampled.times.push(time);
        }
        sampled
    });
    let mut whole = Sampled::with_capacity(bones, times.len());
    runs.into_iter().for_each(|run| whole.append(run));
    whole
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::BoneReport;
    use crate::import::demo_rig;

    #[test]
    fn every_bone_at_every_time_is_what_inspect_reports() {
        // The arrays against `inspect`'s own report of each pose (the same computation, another layout).
        let rig = demo_rig();
        let evaluation = Evaluation::declared(&rig, rig.clips.first());
        let tolerances = Tolerances::default();
        let times: Vec<f64> = (0..300).map(|k| f64::from(k) * 0.01).collect();
        let sampled = sample(&evaluation, &times, &tolerances);
        assert_eq!((sampled.times.as_slice(), sampled.bones), (times.as_slice(), rig.skeleton.len()));
        let mut evaluator = evaluation.evaluator();
        for (t, &time) in times.iter().enumerate() {
            let reports = BoneReport::all(&rig.skeleton, evaluation.modes(), evaluator.evaluate(time), &tolerances);
            for (b, report) in reports.iter().enumerate() {
                let at = |n: usize| (t * sampled.bones + b) * n..(t * sampled.bones + b + 1) * n;
                let rows = |m: &[f64; 16]| DMat4::from_cols_array(m).transpose().to_cols_array().to_vec();
                assert_eq!(sampled.model[at(16)], rows(&report.model.matrix)[..], "model of {b} at {time}");
                assert_eq!(sampled.local[at(16)], rows(&report.local.matrix)[..], "local of {b} at {time}");
                assert_eq!(sampled.translation[at(3)], report.model.translation);
                assert_eq!(sampled.rotation[at(4)], report.model.rotation);
                assert_eq!(sampled.stretch[at(4)], report.model.stretch);
                assert_eq!(sampled.scale[at(3)], report.model.scale);
                assert_eq!(sampled.sign[t * sampled.bones + b], f64::from(report.model.sign));
                assert_eq!(sampled.shear_deg[t * sampled.bones + b], report.shear_deg);
                assert_eq!(sampled.stretched[t * sampled.bones + b], report.stretched);
            }
        }
        assert!(sampled.stretched.iter().any(|&s| s), "the demo's forearm shears");
    }
}
