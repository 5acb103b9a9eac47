//! Blend shapes, as UsdSkel applies them. A mesh bound to a skeleton names its shapes (`skel:blendShapes`, each a
//! `BlendShape` prim through `skel:blendShapeTargets`, in the same order): offsets of the points `pointIndices`
//! lists (of every point where it lists none), and in-between shapes at other weights (`inbetweens:*`). The
//! skeleton's animation weights the shapes by name (`blendShapes`, `blendShapeWeights`).
//!
//! A shape's sub-shapes are its primary shape at weight 1, the rest (no offset) at 0, and its in-betweens at theirs
//! (one at 0 or 1 is left out). A weight `w` falls between the two nearest sub-shapes `a` and `b` — the two lowest
//! below all of them, the two highest above — and is split `(1 − α)` on `a` and `α` on `b`, `α = (w − a)/(b − a)`;
//! a shape without in-betweens takes `w` on its primary shape. Each sub-shape other than the rest becomes a morph
//! target, and the split of the animated weights their weights at every time of the clip: what bonescope skins is
//! then `p + Σ weight · offset`, as for glTF's morph targets.

use glam::Vec3;
use openusd::gf;
use openusd::schemas::skel::{BlendShape, SkelBindingAPI};
use openusd::usd::Stage;

use super::skeleton::ShapeWeights;
use super::{said, within_budget};
use crate::model::{Interpolation, MorphTarget, Track};

/// Pixar's tolerance for a weight or a split being 0 or 1.
const EPS: f32 = 1e-6;

/// A mesh's blend shapes as morph targets, and their weights over the clip (empty where nothing animates them).
pub struct Shapes {
    pub targets: Vec<MorphTarget>,
    pub weights: Vec<Track<f32>>,
}

/// The blend shapes of the mesh `api` binds (`points` points), weighted by its skeleton's animation; `None` where
/// it has none, or names a different number of shapes than it targets (UsdSkel then applies none).
pub fn read(
    stage: &Stage,
    api: &SkelBindingAPI,
    points: usize,
    animated: Option<&ShapeWeights>,
) -> Result<Option<Shapes>, String> {
    let (names, paths) = (api.blend_shapes().map_err(said)?, api.blend_shape_targets().map_err(said)?);
    if names.is_empty() || names.len() != paths.len() {
        return Ok(None);
    }
    let mut targets = Vec::new();
    let mut shapes = Vec::new();
    for (name, path) in names.iter().zip(paths) {
        let Some(shape) = BlendShape::get(stage, path.clone()).map_err(said)? else {
            shapes.push(SubShapes::default());
            continue;
        };
        let indices = shape.point_indices().map_err(said)?;
        let mut sub = vec![(0.0, None)];
        let mut add = |weight: f32, target: String, offsets: &[gf::Vec3f]| -> Result<(), String> {
            within_budget((targets.len() as u64 + 1) * points as u64 * 12, || {
                format!("{} blend shapes", targets.len() + 1)
            })?;
            sub.push((weight, Some(targets.len())));
            targets.push(MorphTarget { name: target, offsets: dense(offsets, &indices, points) });
            Ok(())
        };
        add(1.0, name.clone(), &shape.offsets().map_err(said)?)?;
        for between in shape.inbetweens().map_err(said)? {
            let Some(weight) = between.weight.filter(|w| (w.abs() >= EPS) && (w - 1.0).abs() >= EPS) else { continue };
            add(weight, format!("{name}:{}", between.name), &between.offsets)?;
        }
        sub.sort_by(|a, b| a.0.total_cmp(&b.0));
        shapes.push(SubShapes(sub));
    }
    let weights = animated.map(|a| tracks(a, &names, &shapes, targets.len())).transpose()?.unwrap_or_default();
    Ok(Some(Shapes { targets, weights }))
}

/// A shape's offsets for every point: `offsets[i]` at point `indices[i]` (at point `i` where there are no indices);
/// none where their lengths disagree or an index is not a point (UsdSkel applies no such shape).
fn dense(offsets: &[gf::Vec3f], indices: &[i32], points: usize) -> Vec<Vec3> {
    let mut dense = vec![Vec3::ZERO; points];
    let at: Option<Vec<usize>> = if indices.is_empty() {
        (offsets.len() == points).then(|| (0..points).collect())
    } else {
        let valid = |&i: &i32| usize::try_from(i).ok().filter(|&i| i < points);
        (offsets.len() == indices.len()).then(|| indices.iter().map(valid).collect()).flatten()
    };
    for (point, offset) in at.unwrap_or_default().into_iter().zip(offsets) {
        dense[point] = Vec3::new(offset.x, offset.y, offset.z);
    }
    dense
}

/// One shape's sub-shapes, sorted by weight: `(weight, morph target)`, the rest without a target.
#[derive(Default)]
struct SubShapes(Vec<(f32, Option<usize>)>);

impl SubShapes {
    /// Adds the shares of weight `w` to the targets' `weights`.
    fn split(&self, w: f32, weights: &mut [f32]) {
        let sub = &self.0;
        let mut share = |k: usize, share: f32| {
            if let Some(target) = sub[k].1 {
                weights[target] += share;
            }
        };
        match sub.len() {
            0 | 1 => {}
            // The rest and the primary shape alone: the weight as it is.
            2 => share(1, w),
            n => {
                let above = sub.partition_point(|(weight, _)| *weight <= w);
                let upper = above.clamp(1, n - 1);
                let (a, b) = (sub[upper - 1].0, sub[upper].0);
                if b - a > EPS {
                    let alpha = (w - a) / (b - a);
                    if (alpha - 1.0).abs() >= EPS {
                        share(upper - 1, 1.0 - alpha);
                    }
                    if alpha.abs() >= EPS {
                        share(upper, alpha);
                    }
                }
            }
        }
    }
}

/// The targets' weights at each time of the animation: each shape's animated weight (zero where the animation does
/// not name it) split among its sub-shapes.
fn tracks(
    animated: &ShapeWeights,
    names: &[String],
    shapes: &[SubShapes],
    targets: usize,
) -> Result<Vec<Track<f32>>, String> {
    within_budget(animated.times.len() as u64 * targets as u64 * 4, || format!("{targets} blend-shape weights"))?;
    let channel: Vec<Option<usize>> = names.iter().map(|n| animated.names.iter().position(|a| a == n)).collect();
    let mut values = vec![Vec::with_capacity(animated.times.len()); targets];
    let mut weights = vec![0.0; targets];
    for at in &animated.values {
        weights.fill(0.0);
        for (shape, channel) in shapes.iter().zip(&channel) {
            shape.split(channel.map_or(0.0, |c| at[c]), &mut weights);
        }
        values.iter_mut().zip(&weights).for_each(|(track, &w)| track.push(w));
    }
    let track = |v: Vec<f32>| Track::new(animated.times.clone(), v, Interpolation::Linear).map_err(|e| e.to_string());
    values.into_iter().map(track).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The split of `w` among targets 0 (primary), 1 and 2 (in-betweens at the given weights).
    fn split(inbetweens: &[f32], w: f32) -> Vec<f32> {
        let mut sub = vec![(0.0, None), (1.0, Some(0))];
        sub.extend(inbetweens.iter().enumerate().map(|(k, &weight)| (weight, Some(k + 1))));
        sub.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut weights = vec![0.0; 1 + inbetweens.len()];
        SubShapes(sub).split(w, &mut weights);
        weights
    }

    #[test]
    fn a_weight_splits_between_its_nearest_sub_shapes_as_usdskel_does() {
        // Hand-derived: in-betweens at 0.5 and 1.5 (targetC of Pixar's blend-shape test).
        assert_eq!(split(&[0.5, 1.5], 0.25), vec![0.0, 0.5, 0.0], "half-way from the rest to the 0.5 shape");
        assert_eq!(split(&[0.5, 1.5], 0.75), vec![0.5, 0.5, 0.0]);
        assert_eq!(split(&[0.5, 1.5], 1.0), vec![1.0, 0.0, 0.0], "the primary shape alone");
        assert_eq!(split(&[0.5, 1.5], 2.0), vec![-1.0, 0.0, 2.0], "beyond the last: extrapolated from the two");
        assert_eq!(split(&[0.5, 1.5], -0.5), vec![0.0, -1.0, 0.0], "below the rest: from the rest and 0.5");
        // A negative in-between (targetF, −0.499): −1 extrapolates from it and the rest.
        let below = split(&[-0.499], -1.0);
        assert!(below[0] == 0.0 && (below[1] - 1.0 / 0.499).abs() < 1e-5, "{below:?}");
        // No in-betweens: the weight itself, any value.
        assert_eq!(split(&[], -0.5), vec![-0.5]);
        assert_eq!(split(&[], 2.0), vec![2.0]);
    }

    #[test]
    fn sparse_offsets_land_on_their_points_and_broken_ones_on_none() {
        let offsets = [gf::vec3f(1.0, 0.0, 0.0), gf::vec3f(0.0, 2.0, 0.0)];
        assert_eq!(dense(&offsets, &[2, 0], 3), vec![Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, Vec3::X]);
        assert_eq!(dense(&offsets, &[], 2), vec![Vec3::X, Vec3::new(0.0, 2.0, 0.0)]);
        assert_eq!(dense(&offsets, &[], 3), vec![Vec3::ZERO; 3], "one offset short of the points");
        assert_eq!(dense(&offsets, &[0, 7], 3), vec![Vec3::ZERO; 3], "an index past the points");
    }
}
