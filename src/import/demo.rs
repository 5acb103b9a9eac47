//! The built-in demo rig: the shear that translation, rotation and scale cannot hold. An arm whose upper bone
//! squashes and stretches along its own axis while the forearm bends, so under full scale inheritance the forearm
//! and hand shear; a skinned tube makes the shear visible on a surface. A second clip bends the arm without any
//! stretch.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DQuat, DVec3, Quat, Vec3};

use crate::model::{
    Bone, BoneTracks, Clip, InheritMode, Interpolation, Mesh, NodeRole, Rig, Skeleton, Skin, Track, Transform, Unit,
};

/// Bone indices of the demo rig.
const SHOULDER: usize = 0;
const UPPER_ARM: usize = 1;
const FOREARM: usize = 2;
const HAND: usize = 3;

/// Bone lengths along +X: upper arm, forearm, hand.
const LENGTHS: [f64; 3] = [1.0, 1.0, 0.5];
const TUBE_RADIUS: f32 = 0.16;
const FPS: f64 = 30.0;
const DURATION: f64 = 2.0;

/// The demo rig, made in code (no file).
pub fn demo_rig() -> Rig {
    let skeleton = skeleton();
    let (skin, mesh) = skinned_tube(&skeleton);
    Rig {
        clips: vec![stretch_clip(), bend_clip()],
        skins: vec![skin],
        meshes: vec![mesh],
        notes: vec![
            "built-in demo: the upper arm squashes and stretches along its own axis while the forearm bends".into(),
            "units: metres, Y-up".into(),
        ],
        unit: Some(Unit::METRE),
        skeleton,
        tool: None,
    }
}

fn skeleton() -> Skeleton {
    let bone = |name: &str, parent: Option<usize>, translation: DVec3| Bone {
        name: name.into(),
        node: parent.map_or(0, |p| p + 1),
        parent,
        rest: Transform::from_trs(translation, DQuat::IDENTITY, DVec3::ONE),
        inherit: InheritMode::Full,
        role: NodeRole::Joint,
    };
    Skeleton::new(vec![
        bone("shoulder", None, DVec3::new(0.0, 1.5, 0.0)),
        bone("upper_arm", Some(SHOULDER), DVec3::ZERO),
        bone("forearm", Some(UPPER_ARM), DVec3::X * LENGTHS[0]),
        bone("hand", Some(FOREARM), DVec3::X * LENGTHS[1]),
    ])
    .expect("the demo skeleton is ordered parents first")
}

/// Key times at 30 frames per second over the clip.
fn key_times() -> Arc<[f64]> {
    let frames = (DURATION * FPS).round() as usize;
    (0..=frames).map(|f| f as f64 / FPS).collect()
}

/// The forearm's bend: about Z (in the arm's plane) with a little twist about Y so the shear is not planar.
fn bend(t: f64) -> Quat {
    let phase = (PI * t / DURATION).sin();
    (DQuat::from_rotation_z(75f64.to_radians() * phase) * DQuat::from_rotation_y(20f64.to_radians() * phase)).as_quat()
}

fn rotation_track(times: &Arc<[f64]>, rotation: impl Fn(f64) -> Quat) -> Track<Quat> {
    Track::new(times.clone(), times.iter().map(|&t| rotation(t)).collect::<Arc<[_]>>(), Interpolation::Linear)
        .expect("demo keys are valid")
}

/// The upper arm stretches to 1.6× and squashes to 0.6× along X, keeping its volume; the forearm bends.
fn stretch_clip() -> Clip {
    let times = key_times();
    let scale = |t: f64| {
        let along = 1.0 + 0.6 * (2.0 * PI * t / DURATION).sin().max(-0.66);
        let across = 1.0 / along.sqrt();
        Vec3::new(along as f32, across as f32, across as f32)
    };
    let mut upper = BoneTracks::new(UPPER_ARM);
    upper.scale = Some(
        Track::new(times.clone(), times.iter().map(|&t| scale(t)).collect::<Arc<[_]>>(), Interpolation::Linear)
            .expect("demo keys are valid"),
    );
    let mut forearm = BoneTracks::new(FOREARM);
    forearm.rotation = Some(rotation_track(&times, bend));
    Clip::new(0, Some("stretch".into()), vec![upper, forearm], vec![])
}

/// The same bend with no scale at all: nothing shears.
fn bend_clip() -> Clip {
    let times = key_times();
    let mut forearm = BoneTracks::new(FOREARM);
    forearm.rotation = Some(rotation_track(&times, bend));
    let mut hand = BoneTracks::new(HAND);
    hand.rotation = Some(rotation_track(&times, |t| Quat::from_rotation_z(-(0.5 * (PI * t).sin()) as f32)));
    Clip::new(1, Some("bend".into()), vec![forearm, hand], vec![])
}

/// A tube along the arm, rings every 5 cm, each vertex weighted to the bones whose segment it lies on, blended
/// linearly across 15 cm around each joint.
fn skinned_tube(skeleton: &Skeleton) -> (Skin, Mesh) {
    const SIDES: usize = 16;
    const RING_SPACING: f64 = 0.05;
    const BLEND: f64 = 0.15;
    let total: f64 = LENGTHS.iter().sum();
    let rings = (total / RING_SPACING).round() as usize + 1;
    let joints_of_skin = [UPPER_ARM, FOREARM, HAND];
    let rest = skeleton.rest_model_matrices();
    let origin = rest[UPPER_ARM].w_axis.truncate();
    let (mut positions, mut joints, mut weights) = (Vec::new(), Vec::new(), Vec::new());
    for ring in 0..rings {
        let x = ring as f64 * RING_SPACING;
        let (influences, blend_weights) = ring_weights(x, BLEND);
        for side in 0..SIDES {
            let angle = 2.0 * std::f32::consts::PI * side as f32 / SIDES as f32;
            let offset = Vec3::new(0.0, angle.cos() * TUBE_RADIUS, angle.sin() * TUBE_RADIUS);
            positions.push((origin + DVec3::X * x).as_vec3() + offset);
            joints.push(influences);
            weights.push(blend_weights);
        }
    }
    let mut indices = Vec::new();
    for ring in 0..rings as u32 - 1 {
        for side in 0..SIDES as u32 {
            let next = (side + 1) % SIDES as u32;
            let (a, b) = (ring * SIDES as u32 + side, ring * SIDES as u32 + next);
            let (c, d) = (a + SIDES as u32, b + SIDES as u32);
            indices.extend_from_slice(&[a, c, b, b, c, d]);
        }
    }
    let skin = Skin {
        name: Some("arm".into()),
        joints: joints_of_skin.to_vec(),
        inverse_bind: joints_of_skin.iter().map(|&j| rest[j].inverse()).collect(),
        node_bind: None,
    };
    let mesh = Mesh {
        name: "tube".into(),
        bone: SHOULDER,
        skin: Some(0),
        positions,
        joints,
        weights,
        indices,
        ..Mesh::default()
    };
    (skin, mesh)
}

/// Skin-joint indices and weights of a ring at distance `x` along the arm.
fn ring_weights(x: f64, blend: f64) -> ([u16; 4], [f32; 4]) {
    let elbow = LENGTHS[0];
    let wrist = LENGTHS[0] + LENGTHS[1];
    // Weight of the next bone rises linearly from 0 to 1 across [joint − blend, joint + blend].
    let ramp = |joint: f64| ((x - (joint - blend)) / (2.0 * blend)).clamp(0.0, 1.0) as f32;
    if x < (elbow + wrist) / 2.0 {
        let w = ramp(elbow);
        ([0, 1, 0, 0], [1.0 - w, w, 0.0, 0.0])
    } else {
        let w = ramp(wrist);
        ([1, 2, 0, 0], [1.0 - w, w, 0.0, 0.0])
    }
}

/// A big generated rig for benchmarks: `bones` bones in chains of ten hanging off a spine, a clip of `frames`
/// frames at 30 fps with a rotation key every `key_step` frames on every bone, and a scale key on every tenth bone
/// (so their descendants shear under full inheritance).
pub fn stress_rig(bones: usize, frames: usize, key_step: usize) -> Rig {
    let step = key_step.max(1);
    let key_count = frames / step + 1;
    let times: Arc<[f64]> = (0..key_count).map(|k| (k * step) as f64 / FPS).collect();
    let mut skeleton_bones = Vec::with_capacity(bones);
    let mut tracks = Vec::with_capacity(bones);
    for b in 0..bones {
        // Chains of ten: the first bone of each chain hangs off the root.
        let parent = (b > 0).then(|| if b % 10 == 1 { 0 } else { b - 1 });
        let offset = if b == 0 { DVec3::ZERO } else { DVec3::new(0.0, 0.1, 0.02 * (b % 7) as f64) };
        skeleton_bones.push(Bone {
            name: format!("bone{b}"),
            node: b,
            parent,
            rest: Transform::from_trs(offset, DQuat::IDENTITY, DVec3::ONE),
            inherit: InheritMode::Full,
            role: NodeRole::Joint,
        });
        let phase = b as f64 * 0.37;
        let mut t = BoneTracks::new(b);
        let rotation = |k: usize| {
            let angle = 0.6 * ((k * step) as f64 * 0.05 + phase).sin();
            Quat::from_rotation_z(angle as f32) * Quat::from_rotation_x((0.5 * angle) as f32)
        };
        t.rotation = Some(
            Track::new(times.clone(), (0..key_count).map(rotation).collect::<Arc<[_]>>(), Interpolation::Linear)
                .expect("generated keys are valid"),
        );
        if b % 10 == 5 {
            let scale = |k: usize| {
                let s = 1.0 + 0.4 * ((k * step) as f64 * 0.03 + phase).sin();
                Vec3::new(s as f32, (1.0 / s) as f32, 1.0)
            };
            t.scale = Some(
                Track::new(times.clone(), (0..key_count).map(scale).collect::<Arc<[_]>>(), Interpolation::Linear)
                    .expect("generated keys are valid"),
            );
        }
        tracks.push(t);
    }
    Rig {
        skeleton: Skeleton::new(skeleton_bones).expect("parents come first"),
        clips: vec![Clip::new(0, Some("generated".into()), tracks, vec![])],
        notes: vec![format!("generated: {bones} bones, {frames} frames, a key every {step} frames")],
        unit: Some(Unit::METRE),
        ..Rig::default()
    }
}

#[cfg(test)]
mod tests {
    use glam::DMat4;

    use super::*;
    use crate::analysis::{ScanOptions, scan};
    use crate::eval::Evaluation;

    fn stretched_bones(clip: usize, mode: InheritMode) -> Vec<String> {
        let rig = demo_rig();
        let evaluation = Evaluation::new(&rig, Some(&rig.clips[clip]), &vec![mode; rig.skeleton.len()]).unwrap();
        let result = scan(&evaluation, &ScanOptions::default(), &|_, _| {});
        result.bones.iter().filter(|b| b.stretched()).map(|b| rig.skeleton.bone(b.index).name.clone()).collect()
    }

    #[test]
    fn the_stretch_clip_shears_forearm_and_hand_under_full_inheritance_only() {
        assert_eq!(stretched_bones(0, InheritMode::Full), ["forearm", "hand"]);
        assert!(stretched_bones(0, InheritMode::SegmentCompensate).is_empty());
        assert!(stretched_bones(1, InheritMode::Full).is_empty());
    }

    #[test]
    fn the_stress_rig_has_the_asked_size() {
        let rig = stress_rig(50, 300, 5);
        assert_eq!(rig.skeleton.len(), 50);
        assert!((rig.clips[0].span().length() - 10.0).abs() < 1e-12);
        assert_eq!(rig.clips[0].tracks()[0].rotation.as_ref().unwrap().times().len(), 61);
        assert_eq!(rig.skeleton.parent(11), Some(0));
        assert_eq!(rig.skeleton.parent(12), Some(11));
    }

    #[test]
    fn the_tube_is_bound_at_rest() {
        let rig = demo_rig();
        let mesh = &rig.meshes[0];
        assert_eq!(mesh.positions.len(), mesh.joints.len());
        for w in &mesh.weights {
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        }
        assert!(mesh.indices.iter().all(|&i| (i as usize) < mesh.positions.len()));
        // Inverse bind matrices undo the rest pose: joint matrix = W_rest · IBM = identity.
        let rest = rig.skeleton.rest_model_matrices();
        for (joint, ibm) in rig.skins[0].joints.iter().zip(&rig.skins[0].inverse_bind) {
            assert!((rest[*joint] * *ibm).abs_diff_eq(DMat4::IDENTITY, 1e-12));
        }
    }
}
