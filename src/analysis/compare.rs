//! Two evaluations of one clip side by side: how far each bone's model matrix moves between two sets of
//! inheritance modes (typically the file's declared modes against `full`, what a glTF/TRS engine would do).
//!
//! Per bone and sample: the distance between the two model-space positions (model units) and the angle between
//! the two orientations, each orientation being the rotation `R` of the polar decomposition (the closest rotation
//! to the matrix, so a sheared matrix still has one). The largest of each over the clip is kept, with the first
//! time it happens; differences below [`NOISE`] are rounding and count as none (so their time stays 0).

use rayon::prelude::*;

use super::sample_times;
use crate::eval::{Hierarchy, ModelPose, sample_clip};
use crate::math::{angle_between, decompose_all};
use crate::model::{Clip, Skeleton, Transform};

/// Differences at most this big (model units, degrees) are floating-point rounding, not a difference.
pub const NOISE: f64 = 1e-9;

/// One bone over a whole clip.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BoneDifference {
    pub index: usize,
    /// The largest distance between the two model-space positions, in model units.
    pub max_position_difference: f64,
    /// When it happens (the first such time), in seconds.
    pub position_time: f64,
    /// The largest angle between the two orientations, in degrees.
    pub max_orientation_difference_deg: f64,
    pub orientation_time: f64,
}

impl BoneDifference {
    fn add(&mut self, time: f64, position: f64, angle_deg: f64) {
        if position > self.max_position_difference.max(NOISE) {
            self.max_position_difference = position;
            self.position_time = time;
        }
        if angle_deg > self.max_orientation_difference_deg.max(NOISE) {
            self.max_orientation_difference_deg = angle_deg;
            self.orientation_time = time;
        }
    }

    /// Combines an earlier stretch of time with a later one (ties keep the earlier time).
    fn merge(mut self, later: BoneDifference) -> BoneDifference {
        self.add(later.position_time, later.max_position_difference, 0.0);
        self.add(later.orientation_time, 0.0, later.max_orientation_difference_deg);
        self
    }
}

/// The result of comparing one clip.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipComparison {
    pub samples: usize,
    /// One per bone, in bone order.
    pub bones: Vec<BoneDifference>,
}

/// Compares `clip` (or the rest pose) under `a`'s and `b`'s modes at every key time plus `rate` samples per second.
pub fn compare(skeleton: &Skeleton, clip: Option<&Clip>, a: &Hierarchy, b: &Hierarchy, rate: f64) -> ClipComparison {
    let times = sample_times(clip, rate);
    let empty = || (0..skeleton.len()).map(|index| BoneDifference { index, ..Default::default() }).collect::<Vec<_>>();
    let bones = times
        .par_chunks(64)
        .map(|chunk| {
            let mut local: Vec<Transform> = Vec::new();
            let (mut pose_a, mut pose_b) = (ModelPose::default(), ModelPose::default());
            let mut summaries = empty();
            for &time in chunk {
                match clip {
                    Some(clip) => sample_clip(skeleton, clip, time, &mut local),
                    None => local = skeleton.rest_pose(),
                }
                a.evaluate(&local, &mut pose_a);
                b.evaluate(&local, &mut pose_b);
                let (parts_a, parts_b) = (decompose_all(&pose_a.model), decompose_all(&pose_b.model));
                for ((summary, pa), pb) in summaries.iter_mut().zip(parts_a).zip(parts_b) {
                    let position = (pa.translation - pb.translation).length();
                    let angle = angle_between(pa.rotation, pb.rotation).to_degrees();
                    summary.add(time, position, angle);
                }
            }
            summaries
        })
        .reduce(empty, |earlier, later| earlier.into_iter().zip(later).map(|(x, y)| x.merge(y)).collect());
    ClipComparison { samples: times.len(), bones }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::model::{Bone, InheritMode};

    fn bone(name: &str, parent: Option<usize>, rest: Transform) -> Bone {
        Bone { name: name.into(), node: 0, parent, rest, inherit: InheritMode::Full }
    }

    #[test]
    fn positions_and_orientations_of_a_scaled_chain() {
        // root scaled (2, 1, 1); mid 1 along X, turned 45° about Z, scaled (1, 2, 1); tip 1 along X, turned 30°.
        // Unscaled-parent drops every ancestor's scale: tip at Rz(45°)·(1, 0, 0) + (1, 0, 0), turned 75°.
        // Full: tip at diag(2,1,1)·[(1, 0, 0) + Rz(45°)·diag(1,2,1)·(1, 0, 0)] = (2 + 2c, c, 0) with c = cos 45°,
        // and the linear part M = S0·Rz(45°)·S1·Rz(30°), whose closest rotation turns about Z by
        // atan2(m10 − m01, m00 + m11) (the 2-D polar rotation; computed here without the decomposition code).
        let rz = |deg: f64| Transform::from_trs(DVec3::X, DQuat::from_rotation_z(deg.to_radians()), DVec3::ONE);
        let root = Transform::from_trs(DVec3::ZERO, DQuat::IDENTITY, DVec3::new(2.0, 1.0, 1.0));
        let mid = Transform { scale: DVec3::new(1.0, 2.0, 1.0), ..rz(45.0) };
        let skeleton =
            Skeleton::new(vec![bone("root", None, root), bone("mid", Some(0), mid), bone("tip", Some(1), rz(30.0))])
                .unwrap();
        let unscaled = Hierarchy::new(&skeleton, &[InheritMode::UnscaledParent; 3]);
        let full = Hierarchy::new(&skeleton, &[InheritMode::Full; 3]);
        let result = compare(&skeleton, None, &unscaled, &full, 60.0);
        assert_eq!(result.samples, 1);
        let c = std::f64::consts::FRAC_1_SQRT_2;
        let tip = &result.bones[2];
        let unscaled_tip = DVec3::new(1.0 + c, c, 0.0);
        let full_tip = DVec3::new(2.0 + 2.0 * c, c, 0.0);
        assert!((tip.max_position_difference - (full_tip - unscaled_tip).length()).abs() < 1e-12, "{tip:?}");
        let m = glam::DMat2::from_diagonal(glam::DVec2::new(2.0, 1.0))
            * glam::DMat2::from_angle(45f64.to_radians())
            * glam::DMat2::from_diagonal(glam::DVec2::new(1.0, 2.0))
            * glam::DMat2::from_angle(30f64.to_radians());
        let full_angle = (m.x_axis.y - m.y_axis.x).atan2(m.x_axis.x + m.y_axis.y).to_degrees();
        assert!((tip.max_orientation_difference_deg - (75.0 - full_angle).abs()).abs() < 1e-9, "{tip:?}");
        assert!(tip.max_orientation_difference_deg > 1.0, "the two scales around a rotation turn the tip");
        assert_eq!(result.bones[0], BoneDifference { index: 0, ..Default::default() }, "roots agree in every mode");
    }

    #[test]
    fn angles_between_rotations_are_exact_for_small_and_large_angles() {
        let a = DQuat::from_rotation_y(0.3);
        assert!((angle_between(a, DQuat::from_rotation_y(0.3 + 1e-9)) - 1e-9).abs() < 1e-15);
        assert!((angle_between(a, -DQuat::from_rotation_y(1.3)) - 1.0).abs() < 1e-14);
    }
}
