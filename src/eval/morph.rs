//! Morph targets (blend shapes): the weights at a time, and the positions they give before skinning.
//!
//! A mesh's vertex moves to `v + Σ w_k · offset_k` (glTF's morph targets, FBX's blend shapes, whose in-between
//! shapes the importer has already turned into one weight per shape), then skinning applies as usual. The weights
//! are the clip's where it animates the mesh's bone, else the mesh's own.

use std::borrow::Cow;

use glam::Vec3;

use super::sample::sample_track;
use crate::model::{Clip, Mesh};

/// The animated morph weights of every bone the clip animates them on, at one time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MorphPose {
    /// `(bone, weights)`, sorted by bone.
    animated: Vec<(usize, Vec<f64>)>,
}

impl MorphPose {
    /// Samples the clip's morph weights at `time` (none without a clip: every mesh keeps its own).
    pub fn evaluate(&mut self, clip: Option<&Clip>, time: f64) {
        self.animated.clear();
        let Some(clip) = clip else { return };
        self.animated.extend(
            clip.morph().iter().map(|m| (m.bone, m.weights.iter().map(|track| sample_track(track, time)).collect())),
        );
    }

    /// The weights that apply to `mesh`: the animated ones of its bone when they are one per target, else its own.
    pub fn weights<'a>(&'a self, mesh: &'a Mesh) -> Cow<'a, [f64]> {
        let animated = self.animated.binary_search_by_key(&mesh.bone, |(bone, _)| *bone).ok();
        match animated.map(|i| &self.animated[i].1).filter(|w| w.len() == mesh.morph_targets.len()) {
            Some(weights) => Cow::Borrowed(weights),
            None => Cow::Owned(mesh.morph_weights.iter().map(|&w| f64::from(w)).collect()),
        }
    }

    /// `mesh`'s positions with its morph targets applied (the stored positions when no weight is set).
    pub fn positions<'a>(&self, mesh: &'a Mesh) -> Cow<'a, [Vec3]> {
        let weights = self.weights(mesh);
        let active: Vec<(usize, f32)> =
            weights.iter().enumerate().filter(|(_, w)| **w != 0.0).map(|(k, &w)| (k, w as f32)).collect();
        if active.is_empty() {
            return Cow::Borrowed(&mesh.positions);
        }
        let mut positions = mesh.positions.clone();
        for (k, weight) in active {
            for (p, offset) in positions.iter_mut().zip(&mesh.morph_targets[k].offsets) {
                *p += *offset * weight;
            }
        }
        Cow::Owned(positions)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::model::{Interpolation, MorphTarget, MorphWeights, Track};

    fn mesh() -> Mesh {
        Mesh {
            bone: 2,
            positions: vec![Vec3::ZERO, Vec3::X],
            morph_targets: vec![
                MorphTarget { name: "up".into(), offsets: vec![Vec3::Y, Vec3::Y] },
                MorphTarget { name: "out".into(), offsets: vec![Vec3::ZERO, Vec3::X] },
            ],
            morph_weights: vec![0.5, 0.0],
            ..Mesh::default()
        }
    }

    #[test]
    fn without_a_clip_the_mesh_keeps_its_own_weights() {
        let pose = MorphPose::default();
        assert_eq!(&*pose.positions(&mesh()), [Vec3::new(0.0, 0.5, 0.0), Vec3::new(1.0, 0.5, 0.0)]);
    }

    #[test]
    fn an_animated_bone_takes_the_clip_weights_between_keys() {
        let times: Arc<[f64]> = Arc::from([0.0, 2.0]);
        let track = |a: f32, b: f32| Track::new(times.clone(), vec![a, b], Interpolation::Linear).unwrap();
        let weights = MorphWeights { bone: 2, weights: vec![track(0.0, 1.0), track(1.0, 3.0)] };
        let clip = Clip::new(0, None, vec![], vec![weights]);
        let mut pose = MorphPose::default();
        pose.evaluate(Some(&clip), 0.5);
        // Weights 0.25 and 1.5: (0, 0.25, 0) and (1 + 1.5, 0.25, 0).
        assert_eq!(&*pose.weights(&mesh()), [0.25, 1.5]);
        assert_eq!(&*pose.positions(&mesh()), [Vec3::new(0.0, 0.25, 0.0), Vec3::new(2.5, 0.25, 0.0)]);
        // A mesh on another bone keeps its own.
        let other = Mesh { bone: 1, ..mesh() };
        assert_eq!(&*pose.weights(&other), [0.5, 0.0]);
    }
}
