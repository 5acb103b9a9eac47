//! One UsdSkel `Skeleton` as bones: a node standing for the Skeleton prim (where its Xform ancestors and its own
//! transform put it in the world) and below it the joints, parents first as `joints` lists them (`A/B` is `B`
//! under `A`), resting in their `restTransforms`. The `SkelAnimation` bound to it becomes a clip: per joint it names
//! (in its own order, matched to the skeleton's by path), a track of translations, rotations and scales at every time
//! code of the three attributes and every frame between, each read as UsdSkel reads it there ([`super::samples`]);
//! the other joints rest. Where the Skeleton prim's transform in the world moves, its node has a track too.

use std::sync::Arc;

use glam::{DMat4, Quat, Vec3};
use openusd::schemas::geom::{Imageable, Xformable};
use openusd::schemas::skel::{SkelAnimation, SkelBindingAPI, Skeleton};
use openusd::sdf::{self, Value};
use openusd::usd::{Attribute, Prim, SchemaBase, SchemaKind, Stage, TimeCode};

use super::samples::{Channel, Keys};
use super::{Timing, charge, said};
use crate::math::decompose;
use crate::model::{Bone, BoneTracks, InheritMode, Interpolation, KeyValue, NodeRole, Track, Transform};

/// A skeleton's bones, the tracks of its animation, and where it was placed.
pub struct Read {
    pub bones: Vec<Bone>,
    /// What a user should know of how it was read.
    pub notes: Vec<String>,
    pub animation: Option<Animation>,
    pub placed: Placed,
}

/// Where a skeleton's bones are in the rig, and what its animation weights, for the meshes bound to it.
pub struct Placed {
    pub path: sdf::Path,
    /// The bone standing for the Skeleton prim; its joints follow it, in their order.
    pub node: usize,
    /// The joints' paths (`A/B`).
    pub joints: Vec<String>,
    /// Each joint's `bindTransforms` (empty where they are not one per joint).
    pub bind: Vec<DMat4>,
    /// Its animation's blend-shape weights, where it has any.
    pub weights: Option<ShapeWeights>,
}

/// A SkelAnimation's blend-shape weights: the names it weights (`blendShapes`) and, at each time of the clip, one
/// weight per name (`blendShapeWeights` as USD reads it there; all zero where its length is not theirs).
pub struct ShapeWeights {
    pub names: Vec<String>,
    pub times: Arc<[f64]>,
    pub values: Vec<Vec<f32>>,
}

/// A SkelAnimation's tracks of one skeleton.
pub struct Animation {
    /// The SkelAnimation prim's name.
    pub name: Option<String>,
    pub tracks: Vec<BoneTracks>,
}

/// The skeleton at `path` as bones numbered from `first` (their parents too), and the tracks of its animation.
pub fn read(stage: &Stage, path: &sdf::Path, first: usize, timing: &Timing) -> Result<Read, String> {
    let skeleton = Skeleton::get(stage, path.clone()).map_err(said)?.ok_or("not a Skeleton")?;
    let joints = skeleton.joints().map_err(said)?;
    let parents = skeleton.joint_parent_indices().map_err(said)?;
    let baked_names = written(skeleton.prim(), "names");
    let placing = match written(skeleton.prim(), "placing") {
        Some(Value::IntVec(joints)) => joints,
        _ => Vec::new(),
    };
    // A text layer's reader reads a `string[]` in a dictionary as tokens.
    let baked_names = match baked_names {
        Some(Value::StringVec(names)) => Some(names),
        Some(Value::TokenVec(names)) => Some(names.iter().map(|n| n.as_str().to_owned()).collect()),
        _ => None,
    };
    let ours = baked_names.as_ref().is_some_and(|names| names.len() == joints.len());
    let names = match baked_names {
        Some(names) if ours => names,
        _ => skeleton.joint_short_names().map_err(said)?,
    };
    let rest = rest_transforms(&skeleton, &joints, &parents)?;
    if let Some(j) = rest.iter().position(|m| !m.is_finite()) {
        return Err(format!("the rest transform of joint `{}` is not finite", joints[j]));
    }
    let world = world_transform(stage, path, timing.start)?;
    if !world.is_finite() {
        return Err("its transform in the world is not finite".to_owned());
    }
    let name = path.name().unwrap_or("Skeleton").to_owned();
    // A skeleton bonescope baked stands for no node of its source: its prim only holds the joints.
    let role = if ours { NodeRole::Helper } else { NodeRole::Joint };
    let mut bones = vec![Bone { node: first, role, ..Bone::joint(name, None, transform(&world)) }];
    for (j, joint) in joints.iter().enumerate() {
        let parent = match parents[j] {
            Some(p) if p < j => first + 1 + p,
            Some(_) => return Err(format!("joint `{joint}` comes before its parent in `joints`")),
            None if joint.contains('/') => return Err(format!("joint `{joint}`: its parent is not a joint")),
            None => first,
        };
        let bone = Bone::joint(names[j].clone(), Some(parent), transform(&rest[j]));
        // The joint a bake put above the roots to carry its source's unit and axes only places them.
        let role = if placing.contains(&(j as i32)) { NodeRole::Helper } else { NodeRole::Joint };
        bones.push(Bone { node: first + 1 + j, inherit: InheritMode::Full, role, ..bone });
    }
    let (mut animation, weights) = animation(stage, &skeleton, &joints, first + 1, timing)?.unzip();
    if let Some(moving) = moving_node(stage, path, first, timing)? {
        animation.get_or_insert_with(|| Animation { name: None, tracks: Vec::new() }).tracks.push(moving);
    }
    let bind: Vec<DMat4> = skeleton.bind_transforms().map_err(said)?.iter().map(matrix).collect();
    let notes = [("restTransforms", &rest), ("bindTransforms", &bind)]
        .into_iter()
        .filter_map(|(attribute, matrices)| not_affine_note(path, attribute, matrices, &joints))
        .collect();
    // Bind transforms that are not one per joint, or not finite, bind no mesh (it skins from the geometry's space).
    let bind = if bind.len() == joints.len() && bind.iter().all(DMat4::is_finite) { bind } else { Vec::new() };
    let placed = Placed { path: path.clone(), node: first, joints, bind, weights: weights.flatten() };
    Ok(Read { bones, notes, animation, placed })
}

/// Where some of `matrices` (one per joint) have a last column other than (0, 0, 0, 1) — no rigid transform, as an
/// exporter writes who multiplied every entry by a unit factor — a note naming them: the rest is read without it,
/// the bind check names the binds.
fn not_affine_note(skeleton: &sdf::Path, attribute: &str, matrices: &[DMat4], joints: &[String]) -> Option<String> {
    let off = |m: &&DMat4| (m.row(3) - glam::DVec4::W).abs().max_element() > 1e-9;
    let named: Vec<(&String, &DMat4)> = joints.iter().zip(matrices).filter(|(_, m)| off(m)).collect();
    let (first, matrix) = named.first()?;
    let mut names: Vec<&str> = named.iter().take(4).map(|(n, _)| n.as_str()).collect();
    if named.len() > names.len() {
        names.push("…");
    }
    // To nine decimals (0.01, not 0.010000000000000002), a negative zero as 0.
    let [x, y, z, w] = matrix.row(3).to_array().map(|v| (v * 1e9).round() / 1e9 + 0.0);
    Some(format!(
        "{} of {}: {} of {} joints ({}) have the last column ({x}, {y}, {z}, {w}) at `{first}`, not (0, 0, 0, 1): no \
         rigid transform",
        attribute,
        skeleton.as_str(),
        named.len(),
        joints.len(),
        names.join(", ")
    ))
}

/// What a bake of bonescope's wrote in `prim`'s `customData` under `key`: the names of joints or a mesh as baked,
/// where USD's spelling of names lost them, and the joint that carries the source's unit and axes.
pub fn written(prim: &Prim, key: &str) -> Option<Value> {
    match prim.custom_data().ok()?? {
        Value::Dictionary(mut custom) => match custom.remove(crate::bake::CUSTOM_DATA)? {
            Value::Dictionary(mut ours) => ours.remove(key),
            _ => None,
        },
        _ => None,
    }
}

/// A row-vector USD matrix as bonescope's column-vector one: the same sixteen numbers read by columns.
fn matrix(m: &openusd::gf::Matrix4d) -> DMat4 {
    DMat4::from_cols_array(&m.0)
}

/// A matrix as a local transform, its shear in the stretch rotation and a mirror in the scale's sign.
pub(super) fn transform(m: &DMat4) -> Transform {
    decompose(m).transform()
}

/// Each joint's rest transform relative to its parent: `restTransforms`, or where it is not one per joint, what
/// the world-space `bindTransforms` make of each joint under its parent.
fn rest_transforms(skeleton: &Skeleton, joints: &[String], parents: &[Option<usize>]) -> Result<Vec<DMat4>, String> {
    let rest = skeleton.rest_transforms().map_err(said)?;
    if rest.len() == joints.len() {
        return Ok(rest.iter().map(matrix).collect());
    }
    let bind: Vec<DMat4> = skeleton.bind_transforms().map_err(said)?.iter().map(matrix).collect();
    if bind.len() != joints.len() {
        return Err(format!(
            "{} joints, {} restTransforms and {} bindTransforms: neither is one per joint",
            joints.len(),
            rest.len(),
            bind.len()
        ));
    }
    Ok((0..joints.len()).map(|j| parents[j].map_or(bind[j], |p| bind[p].inverse() * bind[j])).collect())
}

/// Any prim, for reading its transform stack (`xformOpOrder`).
struct Xformed(Prim);

impl SchemaBase for Xformed {
    const KIND: SchemaKind = SchemaKind::ConcreteTyped;

    fn prim(&self) -> &Prim {
        &self.0
    }
}

impl Imageable for Xformed {}
impl Xformable for Xformed {}

/// Where the prim at `path` is in the world at time code `time`: its ancestors' transform stacks and its own,
/// outermost first, from the nearest one that resets the stack.
pub(super) fn world_transform(stage: &Stage, path: &sdf::Path, time: f64) -> Result<DMat4, String> {
    let mut world = DMat4::IDENTITY;
    for xformed in transform_stack(stage, path)? {
        world = matrix(&xformed.local_to_parent_transform(TimeCode::new(time)).map_err(said)?) * world;
    }
    Ok(world)
}

/// The prims whose transforms place the prim at `path` in the world: it and its ancestors, innermost first, up to
/// the nearest that resets the stack (`!resetXformStack!`).
fn transform_stack(stage: &Stage, path: &sdf::Path) -> Result<Vec<Xformed>, String> {
    let mut stack = Vec::new();
    let mut prim_path = Some(path.clone());
    while let Some(current) = prim_path.filter(|p| !p.is_abs_root()) {
        let xformed = Xformed(stage.prim(current.clone()));
        let resets = xformed.resets_xform_stack().map_err(said)?;
        stack.push(xformed);
        if resets {
            break;
        }
        prim_path = current.parent();
    }
    Ok(stack)
}

/// The tracks of the skeleton's bound animation (`skel:animationSource` on it or inherited), its joints' bones
/// numbered from `first`, and its blend-shape weights; `None` without one.
fn animation(
    stage: &Stage,
    skeleton: &Skeleton,
    joints: &[String],
    first: usize,
    timing: &Timing,
) -> Result<Option<(Animation, Option<ShapeWeights>)>, String> {
    let Some(source) = animation_source(stage, skeleton.path())? else {
        return Ok(None);
    };
    let anim = SkelAnimation::get(stage, source.clone()).map_err(said)?.ok_or("not a SkelAnimation")?;
    let anim_joints = anim.joints().map_err(said)?;
    let mapped = skeleton.map_anim_joints(&anim_joints).map_err(said)?;
    let n = mapped.len();
    let shape_names = anim.blend_shapes().map_err(said)?;
    let read = |attribute: Attribute, len: usize| Channel::read(stage, &attribute, len);
    let (translated, rotated) = (read(anim.translations_attr(), n)?, read(anim.rotations_attr(), n)?);
    let scaled = read(anim.scales_attr(), n)?;
    let shape_weights = read(anim.blend_shape_weights_attr(), shape_names.len())?;
    // Samples before the start time code shape what is read from it on, but are not played.
    let channels = [&translated, &rotated, &scaled, &shape_weights];
    let mut codes = sample_codes(channels.into_iter().flatten(), timing.start)?;
    codes.retain(|&code| code >= timing.start);
    if codes.is_empty() {
        codes.push(timing.start);
    }
    // The tracks' keys are charged as they are made (a moving joint's column of samples is its track as it is).
    charge::<f64>(codes.len())?;
    let times: Arc<[f64]> = codes.iter().map(|&c| timing.seconds(c)).collect();
    let translations = tracks(joint_keys(translated, Channel::vectors, &codes, Vec3::ZERO, n)?, &times)?;
    let rotations = tracks(joint_keys(rotated, Channel::rotations, &codes, Quat::IDENTITY, n)?, &times)?;
    let scales = tracks(joint_keys(scaled, Channel::vectors, &codes, Vec3::ONE, n)?, &times)?;
    // UsdSkel's joint transforms are whole TRS: no stretch while the clip plays, one key at its start saying so.
    let no_stretch =
        times.get(..1).and_then(|first| Track::new(first.into(), [Quat::IDENTITY], Interpolation::Step).ok());
    let mut tracks = Vec::new();
    let joint_tracks = translations.into_iter().zip(rotations).zip(scales);
    for (joint, ((translation, rotation), scale)) in mapped.iter().zip(joint_tracks) {
        let Some(j) = joint.filter(|&j| j < joints.len()) else { continue };
        let mut bone = BoneTracks::new(first + j);
        (bone.translation, bone.rotation, bone.scale) = (Some(translation), Some(rotation), Some(scale));
        bone.stretch = no_stretch.clone();
        tracks.push(bone);
    }
    let weights = match shape_names.len() {
        0 => None,
        count => {
            // A weight per shape and time code, read or zero.
            charge::<f32>(codes.len().saturating_mul(count))?;
            let read = shape_weights.as_ref().and_then(|c| c.numbers(&codes));
            let rows = read.unwrap_or_else(|| vec![None; codes.len()]);
            let values = rows.into_iter().map(|row| row.unwrap_or_else(|| vec![0.0; count])).collect();
            Some(ShapeWeights { names: shape_names, times: times.clone(), values })
        }
    };
    Ok(Some((Animation { name: source.name().map(str::to_owned), tracks }, weights)))
}

/// A track of `values` at `times`, linear between them (slerp for rotations), as UsdSkel reads them.
fn linear<T: KeyValue>(times: &Arc<[f64]>, values: impl Into<Arc<[T]>>) -> Result<Track<T>, String> {
    Track::new(times.clone(), values, Interpolation::Linear).map_err(|e| e.to_string())
}

/// Each of the `joints`' keys in `channel` at `codes` (`read` reads them), held at `identity` where there is none.
fn joint_keys<T: Copy>(
    channel: Option<Channel>,
    read: impl FnOnce(Channel, &[f64], T) -> Result<Vec<Keys<T>>, String>,
    codes: &[f64],
    identity: T,
    joints: usize,
) -> Result<Vec<Keys<T>>, String> {
    channel.map_or_else(|| Ok((0..joints).map(|_| Keys::Held(identity)).collect()), |c| read(c, codes, identity))
}

/// A track per element of `keys` at `times`: one key where it holds (an offset, most scales: a clip the size of its
/// motion; between two equal samples USD's rounding may read a value a rounding step off, held, bonescope reads the
/// value itself), else one per time.
fn tracks<T: KeyValue>(keys: Vec<Keys<T>>, times: &Arc<[f64]>) -> Result<Vec<Track<T>>, String> {
    let once: Arc<[f64]> = Arc::from(&times[..1]);
    let track = |keys| match keys {
        Keys::Held(value) => linear(&once, vec![value]),
        Keys::Moving(values) => linear(times, values),
    };
    keys.into_iter().map(track).collect()
}

/// The animation a skeleton plays: the target of the nearest `skel:animationSource` on it or an ancestor (a
/// `SkelRoot` may bind it for every skeleton below), among the prims that apply `SkelBindingAPI`: Pixar's UsdSkel
/// reads the relationship on no other.
fn animation_source(stage: &Stage, skeleton: &sdf::Path) -> Result<Option<sdf::Path>, String> {
    let mut path = Some(skeleton.clone());
    while let Some(current) = path.filter(|p| !p.is_abs_root()) {
        let api = SkelBindingAPI::get(stage, current.clone()).map_err(said)?;
        let targets = api.map(|api| api.animation_source_rel().targets()).transpose().map_err(said)?;
        if let Some(target) = targets.and_then(|t| t.into_iter().next()) {
            return Ok(Some(target));
        }
        path = current.parent();
    }
    Ok(None)
}

/// The time codes an animation is sampled at: every time code of its translations, rotations, scales and blend-shape
/// weights, and every whole time code between the first and the last ([`every_frame`]).
fn sample_codes<'a>(channels: impl Iterator<Item = &'a Channel>, start: f64) -> Result<Vec<f64>, String> {
    every_frame(channels.flat_map(Channel::codes).copied().collect(), start)
}

/// `codes` and every whole time code between the first and the last (USD reads between samples in the precision of
/// the values stored, [`samples`](super::samples): sampled at each frame, the clip holds what it reads there),
/// sorted, once each; `start` where there are none (the attributes' defaults hold throughout).
fn every_frame(mut codes: Vec<f64>, start: f64) -> Result<Vec<f64>, String> {
    codes.sort_by(f64::total_cmp);
    let (Some(&first), Some(&last)) = (codes.first(), codes.last()) else {
        return Ok(vec![start]);
    };
    let frames = (last.floor() - first.ceil()).max(0.0);
    // Charged before they are made: two samples far apart in time are a great many frames.
    charge::<f64>((frames as usize).saturating_add(1))?;
    codes.extend((0..=frames as u64).map(|k| first.ceil() + k as f64));
    codes.sort_by(f64::total_cmp);
    codes.dedup();
    Ok(codes)
}

/// A track for the node standing for the prim at `path` where its transform in the world moves (a time-sampled
/// transform op on it or an ancestor, as a character's Xform carries it through a shot): its world transform at every
/// time code of those ops and every frame between, from `start` on; `None` where it holds still. The stretch stays
/// the rest's (an Xform that shears as it moves is read without the change of its shear).
pub(super) fn moving_node(
    stage: &Stage,
    path: &sdf::Path,
    node: usize,
    timing: &Timing,
) -> Result<Option<BoneTracks>, String> {
    let authored = xform_codes(stage, path)?;
    if authored.len() < 2 {
        return Ok(None);
    }
    let mut codes = every_frame(authored, timing.start)?;
    codes.retain(|&code| code >= timing.start);
    if codes.is_empty() {
        return Ok(None);
    }
    let times: Arc<[f64]> = codes.iter().map(|&c| timing.seconds(c)).collect();
    let (mut translations, mut rotations, mut scales) = (Vec::new(), Vec::new(), Vec::new());
    for &code in &codes {
        let world = world_transform(stage, path, code)?;
        if !world.is_finite() {
            return Err(format!("its transform in the world at time code {code} is not finite"));
        }
        let local = transform(&world);
        translations.push(local.translation.as_vec3());
        rotations.push(local.rotation.as_quat());
        scales.push(local.scale.as_vec3());
    }
    let mut tracks = BoneTracks::new(node);
    tracks.translation = Some(linear(&times, translations)?);
    tracks.rotation = Some(linear(&times, rotations)?);
    tracks.scale = Some(linear(&times, scales)?);
    Ok(Some(tracks))
}

/// The time codes of the transform ops of the prims that place the prim at `path` ([`transform_stack`]), sorted,
/// once each.
fn xform_codes(stage: &Stage, path: &sdf::Path) -> Result<Vec<f64>, String> {
    let mut codes = Vec::new();
    for xformed in transform_stack(stage, path)? {
        let prim = xformed.0.path().clone();
        for op in xformed.xform_op_order().map_err(said)?.unwrap_or_default() {
            let op = op.strip_prefix("!invert!").unwrap_or(&op);
            let Ok(attribute) = prim.append_property(op) else { continue };
            let samples = stage.time_samples(attribute).map_err(said)?.unwrap_or_default();
            codes.extend(samples.iter().map(|(code, _)| *code).filter(|c| c.is_finite()));
        }
    }
    codes.sort_by(f64::total_cmp);
    codes.dedup();
    Ok(codes)
}
