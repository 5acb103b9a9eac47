//! Refusing a rig whose numbers grow past what bonescope computes with: every number it prints must be finite.
//!
//! Each value of a file may be finite and the rig still overflow: a chain of twelve scales of 1e30 is 1e360, BVH
//! offsets of 1e308 add up to infinity. Before a rig is used, an upper bound of every bone's model matrix over every
//! key is found in one pass down the hierarchy: the largest scale factor `s` and translation length `t` a bone takes
//! (at rest or at any key, tangents included; rotations are unit quaternions and never grow a matrix), its model matrix's linear part below `A = A_parent · max(s, 1)` and
//! its origin below `T = T_parent + A_parent · t`. (The factor of at least 1 keeps the bound an upper one under the
//! inheritance modes that leave a parent's scale out.) A bone whose bound passes [`LIMIT`] is refused by name, with
//! the time of its largest key: only there would numbers stop being finite. The limit leaves room for what
//! evaluation does with a matrix: products of three entries (determinants), squares of squares (the decomposition's
//! Gram matrices), and single precision for what is drawn and plotted (a vertex 1e8 from its bone under it). Bones
//! past [`EXTREME`] load, and a note names the first: no runtime keeps such numbers to a useful precision.

use glam::{DVec3, Vec3};

use super::failure::{Failure, Result};
use crate::model::{Clip, Rig, Track};

/// The largest model-matrix entry bonescope computes with: its fourth power (1e120) stays far from `f64::MAX`
/// (1.8e308), and a vertex 1e8 from its bone under it stays a finite single-precision number (below 3.4e38).
pub const LIMIT: f64 = 1e30;

/// Model-matrix entries past this load with a note: a runtime's single precision keeps seven digits of them, so a
/// bone at 1e20 moves in steps of 1e13.
pub const EXTREME: f64 = 1e20;

/// The largest magnitude a bone's local part takes, and when (`None`: at rest).
#[derive(Clone, Copy)]
struct Largest {
    value: f64,
    time: Option<f64>,
}

impl Largest {
    fn at_rest(value: f64) -> Self {
        Largest { value, time: None }
    }

    fn keep(&mut self, value: f64, time: f64) {
        if value > self.value {
            *self = Largest { value, time: Some(time) };
        }
    }
}

/// Refuses `rig` when some bone's model matrix can pass [`LIMIT`] at rest or in some clip; else the note to add where
/// some can pass [`EXTREME`].
pub(super) fn check(rig: &Rig) -> Result<Option<String>> {
    let bones = rig.skeleton.bones();
    let mut scale: Vec<Largest> = bones.iter().map(|b| Largest::at_rest(b.rest.scale.abs().max_element())).collect();
    let mut translation: Vec<Largest> = bones.iter().map(|b| Largest::at_rest(length(b.rest.translation))).collect();
    for clip in &rig.clips {
        widen(clip, &mut scale, &mut translation);
    }
    let mut linear = vec![1.0f64; bones.len()];
    let mut origin = vec![0.0f64; bones.len()];
    let mut extreme: Option<(usize, usize)> = None;
    for (index, bone) in bones.iter().enumerate() {
        let (parent_linear, parent_origin) = bone.parent.map_or((1.0, 0.0), |p| (linear[p], origin[p]));
        linear[index] = parent_linear * scale[index].value.max(1.0);
        origin[index] = parent_origin + parent_linear * translation[index].value;
        // Written so that a bound that is not a number (infinity times zero) is refused too.
        let within = linear[index] <= LIMIT && origin[index] <= LIMIT;
        if !within {
            let (what, largest) =
                if linear[index] > LIMIT { ("scale", scale[index]) } else { ("translation", translation[index]) };
            let when = largest.time.map_or_else(|| "at rest".to_owned(), |t| format!("at {t} s"));
            let message = format!(
                "its model matrix can reach {:.1e} (its {what} is {:.3e} {when}, under its parents'): beyond the \
                 {LIMIT:.0e} bonescope computes with",
                linear[index].max(origin[index]),
                largest.value,
            );
            return Err(Failure::at(format!("bone `{}`", bone.name), message));
        }
        if linear[index].max(origin[index]) > EXTREME {
            let (first, count) = extreme.unwrap_or((index, 0));
            extreme = Some((first, count + 1));
        }
    }
    Ok(extreme.map(|(first, count)| {
        let reach = linear[first].max(origin[first]);
        format!(
            "model matrices can reach {reach:.1e} at bone `{}` ({count} bones past {EXTREME:.0e}): evaluated, but no \
             runtime's single precision keeps such numbers",
            bones[first].name
        )
    }))
}

/// Widens each bone's largest scale and translation by the keys of `clip`.
fn widen(clip: &Clip, scale: &mut [Largest], translation: &mut [Largest]) {
    for tracks in clip.tracks() {
        if let Some(track) = &tracks.scale {
            largest_of(track, |v| f64::from(v.abs().max_element()), &mut scale[tracks.bone]);
        }
        if let Some(track) = &tracks.translation {
            largest_of(track, |t: Vec3| length(t.as_dvec3()), &mut translation[tracks.bone]);
        }
    }
}

/// Widens `largest` by every stored value of `track` (tangents included), measured by `size`.
fn largest_of<T: Copy>(track: &Track<T>, size: impl Fn(T) -> f64, largest: &mut Largest) {
    let per_key = track.interpolation().values_per_key();
    for (i, &value) in track.values().iter().enumerate() {
        largest.keep(size(value), track.times()[i / per_key]);
    }
}

/// The length of `v`, scaled so that squaring cannot overflow where the length itself is finite (offsets of 1e308).
fn length(v: DVec3) -> f64 {
    let largest = v.abs().max_element();
    if largest == 0.0 { 0.0 } else { largest * (v / largest).length() }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::DQuat;

    use super::*;
    use crate::model::{Bone, BoneTracks, InheritMode, Interpolation, NodeRole, Skeleton, Transform};

    /// A chain of bones, each scaled by `scale` and moved by `offset` at rest.
    fn chain(depth: usize, scale: f64, offset: f64) -> Rig {
        let bones = (0..depth)
            .map(|i| Bone {
                name: format!("b{i}"),
                node: i,
                parent: i.checked_sub(1),
                rest: Transform::from_trs(DVec3::new(offset, 0.0, 0.0), DQuat::IDENTITY, DVec3::splat(scale)),
                inherit: InheritMode::Full,
                role: NodeRole::Joint,
            })
            .collect();
        Rig { skeleton: Skeleton::new(bones).unwrap(), ..Rig::default() }
    }

    #[test]
    fn chains_within_the_limit_pass() {
        assert!(matches!(check(&chain(12, 10.0, 1e3)), Ok(None)), "1e12 scale, origins near 1e14");
        assert!(matches!(check(&chain(500, 0.5, 1e3)), Ok(None)), "shrinking scales never grow");
        // A scale of 1e12 twice: 1e24, finite everywhere, loads with a note naming the first bone past 1e20.
        let note = check(&chain(2, 1e12, 1.0)).unwrap().expect("a note");
        assert!(note.starts_with("model matrices can reach 1.0e24 at bone `b1` (1 bones past 1e20)"), "{note}");
    }

    #[test]
    fn a_chain_of_large_scales_is_refused_at_the_bone_that_passes() {
        // 1e5 per level: the sixth bone reaches 1e30, the limit, where the product of six 1e5s rounds just past it;
        // the fifth (1e25) loads.
        let failure = check(&chain(12, 1e5, 1.0)).unwrap_err();
        assert_eq!(failure.place.as_deref(), Some("bone `b5`"));
        assert!(failure.message.contains("at rest"), "{}", failure.message);
        // Offsets of 1e308 pass the limit at the first bone, without any scale.
        let failure = check(&chain(4, 1.0, 1e308)).unwrap_err();
        assert_eq!(failure.place.as_deref(), Some("bone `b0`"));
    }

    #[test]
    fn lengths_do_not_overflow_before_they_must() {
        assert_eq!(length(DVec3::new(3.0, 4.0, 0.0)), 5.0);
        assert_eq!(length(DVec3::new(1e308, 1e308, 0.0)), 1e308 * 2f64.sqrt());
        assert_eq!(length(DVec3::ZERO), 0.0);
    }

    #[test]
    fn keys_count_with_their_time() {
        let mut rig = chain(3, 1.0, 1.0);
        let times: Arc<[f64]> = Arc::from([0.0, 0.5]);
        let values = vec![Vec3::ONE, Vec3::splat(1e15)];
        let mut tracks = BoneTracks::new(1);
        tracks.scale = Some(Track::new(times, values, Interpolation::Linear).unwrap());
        rig.clips.push(Clip::new(0, None, vec![tracks], vec![]));
        assert!(matches!(check(&rig), Ok(None)), "1e15 is under the limit");
        rig.clips[0] = {
            let mut tracks = BoneTracks::new(2);
            let times: Arc<[f64]> = Arc::from([0.0, 0.5]);
            tracks.scale = Some(Track::new(times, vec![Vec3::ONE, Vec3::splat(1e35)], Interpolation::Linear).unwrap());
            Clip::new(0, None, vec![tracks], vec![])
        };
        let failure = check(&rig).unwrap_err();
        assert_eq!(failure.place.as_deref(), Some("bone `b2`"));
        assert!(failure.message.contains("at 0.5 s"), "{}", failure.message);
    }
}
