//! Runtime techniques layered on clips (`eval::layers`), against values computed by hand from their formulas, and
//! the walk–run sync on real motion capture.

mod common;

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use bonescope::eval::layers::{
    Additive, AdditiveOrder, AdditiveReference, Blend, Crossfade, FadeCurve, LayerError, Resampling, RotationBlend,
    Shake, ShakeParams, SyncedCycle, Target, add, difference,
};
use bonescope::eval::{Hierarchy, LayerStack, Layers, Pose, bind_pose};
use bonescope::import::{self, demo_rig};
use bonescope::math::decompose;
use bonescope::model::{Bone, BoneTracks, Clip, InheritMode, Interpolation, NodeRole, Rig, Skeleton, Track, Transform};
use common::asset;
use glam::{DMat4, DQuat, DVec3, Vec3};
use proptest::prelude::*;

/// One root bone and clips that move it along X linearly: `(duration, speed)` each, so x = speed · t.
fn sliding_rig(clips: &[(f64, f64)]) -> Rig {
    let bone = Bone {
        name: "root".into(),
        node: 0,
        parent: None,
        rest: Transform::IDENTITY,
        inherit: InheritMode::Full,
        role: NodeRole::Joint,
    };
    let clips = clips
        .iter()
        .enumerate()
        .map(|(index, &(duration, speed))| {
            let mut tracks = BoneTracks::new(0);
            let values = vec![Vec3::ZERO, Vec3::new((duration * speed) as f32, 0.0, 0.0)];
            tracks.translation =
                Some(Track::new(Arc::from([0.0, duration].as_slice()), values, Interpolation::Linear).unwrap());
            Clip::new(index, Some(format!("clip{index}")), vec![tracks], vec![])
        })
        .collect();
    Rig { skeleton: Skeleton::new(vec![bone]).unwrap(), clips, ..Rig::default() }
}

fn root_x(rig: &Rig, layers: &Layers, time: f64) -> f64 {
    let mut stack = LayerStack::new(rig, layers).unwrap();
    let mut local = Vec::new();
    stack.evaluate(rig, rig.clips.first(), time, &mut local);
    local[0].translation.x
}

#[test]
fn synced_blend_plays_both_clips_at_one_phase_of_the_blended_cycle() {
    // Walk 1.2 s at x = 10·t, run 0.8 s at x = 20·t; a = 0.25, synced: cycle 1.1 s, rates 1.0909 and 0.7273.
    // At 0.55 s (half the cycle) walk is at 0.6 s (x = 6) and run at 0.4 s (x = 8): 0.75·6 + 0.25·8 = 6.5.
    let rig = sliding_rig(&[(1.2, 10.0), (0.8, 20.0)]);
    let blend = Blend { clip: 1, weight: 0.25, sync: true, rotation: RotationBlend::Slerp };
    let layers = Layers { blend: Some(blend), ..Layers::default() };
    assert!((root_x(&rig, &layers, 0.55) - 6.5).abs() < 1e-5);
    // The cycle wraps at 1.1 s.
    assert!((root_x(&rig, &layers, 1.65) - 6.5).abs() < 1e-5);
    let stack = LayerStack::new(&rig, &layers).unwrap();
    let cycle = stack.synced_cycle(&rig, rig.clips.first()).unwrap();
    assert_eq!(cycle, SyncedCycle::new(1.2, 0.8, 0.25));
    assert!((cycle.length - 1.1).abs() < 1e-15 && (stack.length(&rig, rig.clips.first()) - 1.1).abs() < 1e-15);
    // Without sync both play at their own speed: walk at 0.55 s (5.5), run at 0.55 s (11): 4.125 + 2.75 = 6.875.
    let unsynced = Layers { blend: Some(Blend { sync: false, ..blend }), ..Layers::default() };
    assert!((root_x(&rig, &unsynced, 0.55) - 6.875).abs() < 1e-5);
}

#[test]
fn additive_rotations_depend_on_the_order() {
    // Base clip: the bone turned 90° about Z; additive clip: 90° about X, its difference from the rest pose.
    let rotation_clip = |index, q: DQuat| {
        let mut tracks = BoneTracks::new(0);
        let times: Arc<[f64]> = Arc::from([0.0, 1.0].as_slice());
        tracks.rotation = Some(Track::new(times, vec![q.as_quat(); 2], Interpolation::Linear).unwrap());
        Clip::new(index, None, vec![tracks], vec![])
    };
    let mut rig = sliding_rig(&[]);
    rig.clips =
        vec![rotation_clip(0, DQuat::from_rotation_z(FRAC_PI_2)), rotation_clip(1, DQuat::from_rotation_x(FRAC_PI_2))];
    let y_goes_to = |order, weight| {
        let additive = Additive { clip: 1, reference: AdditiveReference::Rest, order, weight };
        let layers = Layers { additive: Some(additive), ..Layers::default() };
        let mut local = Vec::new();
        LayerStack::new(&rig, &layers).unwrap().evaluate(&rig, rig.clips.first(), 0.5, &mut local);
        local[0].rotation * DVec3::Y
    };
    // Local: Rz·Rx·Y = Rz·Z = Z. Global: Rx·Rz·Y = Rx·(−X) = −X.
    assert!(y_goes_to(AdditiveOrder::Local, 1.0).abs_diff_eq(DVec3::Z, 1e-12));
    assert!(y_goes_to(AdditiveOrder::Global, 1.0).abs_diff_eq(-DVec3::X, 1e-12));
    // Half the additive: 45° about X after (local) or before (global) the base turn.
    let half = std::f64::consts::FRAC_1_SQRT_2;
    assert!(y_goes_to(AdditiveOrder::Local, 0.5).abs_diff_eq(DVec3::new(-half, 0.0, half), 1e-12));
    // Global: Rx(45°)·Rz·Y = Rx(45°)·(−X) = −X, a turn about X leaves X alone.
    assert!(y_goes_to(AdditiveOrder::Global, 0.5).abs_diff_eq(-DVec3::X, 1e-12));
    // The first frame as reference: the clip is constant, so it adds nothing.
    let additive = Additive { clip: 1, reference: AdditiveReference::First, order: AdditiveOrder::Local, weight: 1.0 };
    let layers = Layers { additive: Some(additive), ..Layers::default() };
    let mut local = Vec::new();
    LayerStack::new(&rig, &layers).unwrap().evaluate(&rig, rig.clips.first(), 0.5, &mut local);
    assert!(local[0].rotation.abs_diff_eq(DQuat::from_rotation_z(FRAC_PI_2), 1e-7));
}

#[test]
fn the_bind_weight_mixes_the_clip_with_the_bind_pose() {
    // The demo's forearm bound 1 rad about Z (not its rest pose); the "bend" clip bends it.
    let mut rig = demo_rig();
    let elbow = DMat4::from_rotation_translation(DQuat::from_rotation_z(1.0), DVec3::new(1.0, 1.5, 0.0));
    rig.skins[0].inverse_bind[1] = elbow.inverse();
    let bend = Some(&rig.clips[1]);
    let evaluate = |weight: f64| {
        let mut local = Vec::new();
        let layers = Layers { bind_weight: weight, ..Layers::default() };
        LayerStack::new(&rig, &layers).unwrap().evaluate(&rig, bend, 0.5, &mut local);
        local
    };
    let bind = bind_pose(&rig);
    let clip = evaluate(1.0);
    let at_bind = evaluate(0.0);
    assert!(at_bind[2].rotation.abs_diff_eq(DQuat::from_rotation_z(1.0), 1e-12));
    assert_eq!(at_bind, bind);
    // Half way: slerp of the two rotations at 0.5, i.e. the bind rotation turned half the way to the clip's.
    let half = evaluate(0.5);
    let expected = bind[2].rotation.slerp(clip[2].rotation, 0.5);
    assert!(half[2].rotation.abs_diff_eq(expected, 1e-12));
}

#[test]
fn a_crossfade_runs_from_the_end_of_one_clip_into_the_start_of_another() {
    // Clip 0: x = 10·t for 1 s. Clip 1: x = 20·t for 1 s. Fade at 0.8 s over 0.4 s.
    let rig = sliding_rig(&[(1.0, 10.0), (1.0, 20.0)]);
    let fade = Crossfade { clip: 1, at: 0.8, duration: 0.4, curve: FadeCurve::Linear };
    let layers = Layers { crossfade: Some(fade), ..Layers::default() };
    assert!((root_x(&rig, &layers, 0.7) - 7.0).abs() < 1e-5, "before the fade: clip 0 alone");
    // At 1.0 s: weight 0.5; clip 0 at its end (x = 10), clip 1 at 0.2 s (x = 4): 7.
    assert!((root_x(&rig, &layers, 1.0) - 7.0).abs() < 1e-5);
    // At 0.9 s: weight 0.25; clip 0 at 9, clip 1 at 0.1 s (2): 0.75·9 + 0.25·2 = 7.25.
    assert!((root_x(&rig, &layers, 0.9) - 7.25).abs() < 1e-5);
    // Smoothstep at a quarter of the fade: 0.15625. 0.84375·9 + 0.15625·2 = 7.90625.
    let smooth = Layers { crossfade: Some(Crossfade { curve: FadeCurve::Smooth, ..fade }), ..Layers::default() };
    assert!((root_x(&rig, &smooth, 0.9) - 7.90625).abs() < 1e-5);
    // After the fade: clip 1 alone, at 1.5 − 0.8 = 0.7 s.
    assert!((root_x(&rig, &layers, 1.5) - 14.0).abs() < 1e-5);
    let stack = LayerStack::new(&rig, &layers).unwrap();
    assert!((stack.length(&rig, rig.clips.first()) - 1.8).abs() < 1e-12, "the timeline runs to the end of clip 1");
}

#[test]
fn the_shake_grows_down_the_arm() {
    // Demo arm, shake on the upper arm with the default parameters, at t = 0: factor 0.3, modifiers 1, 1.3, 1.6:
    // translations (0, 0.3, 0), (0, 0.39, 0), (0, 0.48, 0) added; the shoulder above stays.
    let rig = demo_rig();
    let layers = Layers { shake: Some(Shake { bone: 1, params: ShakeParams::default() }), ..Layers::default() };
    let mut local = Vec::new();
    LayerStack::new(&rig, &layers).unwrap().evaluate(&rig, None, 0.0, &mut local);
    let rest = rig.skeleton.rest_pose();
    assert_eq!(local[0], rest[0]);
    for (bone, lift) in [(1, 0.3), (2, 0.39), (3, 0.48)] {
        let moved = local[bone].translation - rest[bone].translation;
        assert!(moved.abs_diff_eq(DVec3::new(0.0, lift, 0.0), 1e-12), "{bone}: {moved:?}");
        // Rotation (0, 0.1, 0) · the same factor: 0.1·lift radians about Y.
        assert!(local[bone].rotation.abs_diff_eq(DQuat::from_rotation_y(0.1 * lift), 1e-12));
    }
}

#[test]
fn a_target_pins_the_model_rotation() {
    // The demo's bend clip turns the forearm; pin it to 30° about Y in model space.
    let rig = demo_rig();
    let target = DQuat::from_rotation_y(30f64.to_radians());
    let layers = Layers { targets: vec![Target { bone: 2, rotation: target, weight: 1.0 }], ..Layers::default() };
    let mut stack = LayerStack::new(&rig, &layers).unwrap();
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut pose = Pose::default();
    for time in [0.0, 0.7, 1.3] {
        pose.evaluate_layered(&rig, Some(&rig.clips[1]), &hierarchy, &mut stack, time);
        let model = decompose(&pose.model.model[2]).rotation;
        assert!(model.angle_between(target) < 1e-9, "t = {time}: {model:?}");
    }
}

#[test]
fn interpolation_applies_to_every_clip_a_layer_reads() {
    // Keys at 0 and 1 s; nearest key at 0.4 s is the first: x = 0 for clip 0, and the blend's clip 1 too.
    let rig = sliding_rig(&[(1.0, 10.0), (1.0, 20.0)]);
    let nearest = Resampling { keys: bonescope::eval::layers::KeyInterpolation::Nearest, ..Resampling::default() };
    let blend = Blend { clip: 1, weight: 0.5, sync: false, rotation: RotationBlend::Nlerp };
    let layers = Layers { interpolation: nearest, blend: Some(blend), ..Layers::default() };
    assert_eq!(root_x(&rig, &layers, 0.4), 0.0);
    assert!((root_x(&rig, &layers, 0.6) - 15.0).abs() < 1e-5);
}

#[test]
fn indices_are_checked_and_bad_values_never_panic() {
    let rig = demo_rig();
    let blend = Blend { clip: 9, weight: 0.5, sync: true, rotation: RotationBlend::Slerp };
    let error = LayerStack::new(&rig, &Layers { blend: Some(blend), ..Layers::default() }).unwrap_err();
    assert_eq!(error, LayerError::NoClip { layer: "blend", index: 9, count: 2 });
    assert_eq!(error.to_string(), "blend: no animation 9 (the file has 2)");
    let shake = Shake { bone: 4, params: ShakeParams::default() };
    assert!(matches!(
        LayerStack::new(&rig, &Layers { shake: Some(shake), ..Layers::default() }),
        Err(LayerError::NoBone { layer: "shake", index: 4, count: 4 })
    ));
    // NaN and out-of-range weights, NaN times, a zero-length clip in a synced blend: finite poses.
    let mut zero = sliding_rig(&[(1.0, 1.0)]);
    zero.clips.push(Clip::new(1, None, vec![], vec![]));
    let layers = Layers {
        bind_weight: f64::NAN,
        blend: Some(Blend { clip: 1, weight: 7.0, sync: true, rotation: RotationBlend::Nlerp }),
        additive: Some(Additive {
            clip: 1,
            reference: AdditiveReference::First,
            order: AdditiveOrder::Global,
            weight: f64::NAN,
        }),
        crossfade: Some(Crossfade { clip: 1, at: f64::NAN, duration: -1.0, curve: FadeCurve::Smooth }),
        shake: Some(Shake { bone: 0, params: ShakeParams { speed: f64::INFINITY, ..ShakeParams::default() } }),
        targets: vec![Target { bone: 0, rotation: DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0), weight: f64::NAN }],
        ..Layers::default()
    };
    let mut stack = LayerStack::new(&zero, &layers).unwrap();
    let mut local = Vec::new();
    for time in [f64::NAN, -1.0, 0.0, 0.5, f64::INFINITY] {
        stack.evaluate(&zero, zero.clips.first(), time, &mut local);
        let t = local[0];
        assert!(t.translation.is_finite() && t.rotation.is_finite() && t.scale.is_finite(), "{time}: {t:?}");
    }
}

#[test]
fn the_default_layers_are_the_clip_as_sampled() {
    let rig = demo_rig();
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut stack = LayerStack::new(&rig, &Layers::default()).unwrap();
    let (mut plain, mut layered) = (Pose::default(), Pose::default());
    for time in [0.0, 0.25, 1.9] {
        plain.evaluate(&rig.skeleton, Some(&rig.clips[0]), &hierarchy, time);
        layered.evaluate_layered(&rig, Some(&rig.clips[0]), &hierarchy, &mut stack, time);
        assert_eq!(plain.local, layered.local);
    }
    assert!(Layers::default().is_empty());
    // The settings round-trip through JSON, and missing fields take their defaults.
    let layers = Layers {
        bind_weight: 0.5,
        targets: vec![Target { bone: 1, rotation: DQuat::IDENTITY, weight: 1.0 }],
        ..Layers::default()
    };
    let json = serde_json::to_string(&layers).unwrap();
    assert_eq!(serde_json::from_str::<Layers>(&json).unwrap(), layers);
    assert_eq!(serde_json::from_str::<Layers>("{}").unwrap(), Layers::default());
}

fn transform() -> impl Strategy<Value = Transform> {
    let v = || (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    let axis = (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, 0.0..3.1f64)
        .prop_filter("an axis", |(x, y, z, _)| x * x + y * y + z * z > 0.01)
        .prop_map(|(x, y, z, a)| DQuat::from_axis_angle(DVec3::new(x, y, z).normalize(), a));
    let s = (0.1..4.0f64, 0.1..4.0f64, 0.1..4.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z));
    (v(), axis, s).prop_map(|(t, r, s)| Transform::from_trs(t, r, s))
}

proptest! {
    #[test]
    fn adding_a_difference_to_its_reference_restores_the_sample(sample in transform(), reference in transform()) {
        for order in [AdditiveOrder::Local, AdditiveOrder::Global] {
            let back = add(&reference, &difference(&sample, &reference, order), 1.0, order);
            prop_assert!(back.translation.abs_diff_eq(sample.translation, 1e-12));
            prop_assert!(back.rotation.dot(sample.rotation).abs() > 1.0 - 1e-12);
            prop_assert!(back.scale.abs_diff_eq(sample.scale, 1e-12));
        }
    }

    #[test]
    fn blends_stay_between_their_ends(a in transform(), b in transform(), w in 0.0..1.0f64) {
        for rotation in [RotationBlend::Slerp, RotationBlend::Nlerp] {
            let m = bonescope::eval::layers::mix(&a, &b, w, rotation);
            prop_assert!((m.rotation.length() - 1.0).abs() < 1e-12);
            // The mixed rotation lies on the arc: its angles to the ends add up to the angle between them.
            let to_a = m.rotation.angle_between(a.rotation);
            let to_b = m.rotation.angle_between(b.rotation);
            let ab = a.rotation.angle_between(b.rotation);
            prop_assert!((to_a + to_b - ab).abs() < 1e-6, "{to_a} + {to_b} vs {ab}");
            prop_assert!(m.translation.distance(a.translation) <= a.translation.distance(b.translation) + 1e-9);
        }
    }
}

/// A linear track of 1–8 keys at increasing times with values in ±100.
fn vector_track() -> impl Strategy<Value = Track<Vec3>> {
    prop::collection::vec((0.01..1.0f64, -100.0..100.0f32), 1..8).prop_map(|keys| {
        let times: Vec<f64> = keys.iter().scan(0.0, |t, (step, _)| Some(std::mem::replace(t, *t + step))).collect();
        let values: Vec<_> = keys.iter().map(|&(_, x)| Vec3::new(x, -x, 0.5 * x)).collect();
        Track::new(Arc::from(times), values, Interpolation::Linear).unwrap()
    })
}

proptest! {
    #[test]
    fn every_interpolation_passes_through_the_keys_and_stays_finite(track in vector_track(), at in -1.0..9.0f64) {
        use bonescope::eval::layers::KeyInterpolation::{Authored, Cubic, Linear, Nearest};
        for keys in [Authored, Nearest, Linear, Cubic] {
            let resampling = Resampling { keys, ..Resampling::default() };
            prop_assert!(resampling.sample(&track, at).is_finite());
            for (time, value) in track.times().iter().zip(track.values()) {
                prop_assert_eq!(resampling.sample(&track, *time), value.as_dvec3());
            }
            // Nearest and linear never leave the range of the keys (cubic may overshoot).
            if keys != Cubic {
                let x = resampling.sample(&track, at).x;
                let xs = track.values().iter().map(|v| f64::from(v.x));
                let (lo, hi) = xs.fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)));
                prop_assert!(lo - 1e-9 <= x && x <= hi + 1e-9);
            }
        }
    }
}

fn locomotions() -> Rig {
    import::load(&asset("fbx-proanimationbank/locomotions.fbx")).expect("the locomotion cycles load")
}

/// When in its cycle a foot is planted: the circular mean of the phases at which `bone` is within a quarter of its
/// height range of its lowest (model-space height, `steps` evenly spaced phases of a cycle of `length` seconds of
/// clip `clip` under `layers`). The lowest point alone is no good: a walking foot lies flat for half the cycle.
fn stance_phase(rig: &Rig, clip: usize, layers: &Layers, length: f64, bone: usize, steps: usize) -> f64 {
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let mut stack = LayerStack::new(rig, layers).unwrap();
    let mut pose = Pose::default();
    let heights: Vec<f64> = (0..steps)
        .map(|i| {
            pose.evaluate_layered(
                rig,
                Some(&rig.clips[clip]),
                &hierarchy,
                &mut stack,
                length * i as f64 / steps as f64,
            );
            pose.model.model[bone].w_axis.y
        })
        .collect();
    let (low, high) = heights.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &y| (l.min(y), h.max(y)));
    let planted = low + 0.25 * (high - low);
    let (sin, cos) = heights.iter().enumerate().filter(|(_, y)| **y <= planted).fold((0.0, 0.0), |(s, c), (i, _)| {
        let angle = std::f64::consts::TAU * i as f64 / steps as f64;
        (s + angle.sin(), c + angle.cos())
    });
    f64::atan2(sin, cos).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU
}

/// Distance between two phases on the circle.
fn phase_distance(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(1.0);
    d.min(1.0 - d)
}

#[test]
fn a_synced_walk_run_blend_plants_the_feet_at_the_same_phases() {
    let rig = locomotions();
    let index = |name: &str| rig.clips.iter().position(|c| c.name.as_deref() == Some(name)).unwrap();
    let (walk, run) = (index("walk"), index("run"));
    let (t1, t2) = (rig.clips[walk].span().length(), rig.clips[run].span().length());
    assert!((t1 - 4.0 / 3.0).abs() < 0.01 && (t2 - 2.0 / 3.0).abs() < 0.01, "{t1} {t2}");
    const STEPS: usize = 200;
    for foot in ["LeftFoot", "RightFoot"] {
        let bone = rig.skeleton.find(foot).unwrap();
        let none = Layers::default();
        let walk_phase = stance_phase(&rig, walk, &none, t1, bone, STEPS);
        let run_phase = stance_phase(&rig, run, &none, t2, bone, STEPS);
        // The animators matched the cycles (what a synced blend needs): each foot plants at nearly the same phase.
        assert!(phase_distance(walk_phase, run_phase) < 0.1, "{foot}: walk {walk_phase:.3}, run {run_phase:.3}");
        for a in [0.25, 0.5, 0.75] {
            let blend = Blend { clip: run, weight: a, sync: true, rotation: RotationBlend::Slerp };
            let cycle = SyncedCycle::new(t1, t2, a);
            let layers = Layers { blend: Some(blend), ..Layers::default() };
            let blend_phase = stance_phase(&rig, walk, &layers, cycle.length, bone, STEPS);
            // Synced, the blended cycle plants the foot at that phase too: between (or at) the two clips' phases.
            let span = phase_distance(walk_phase, run_phase);
            let from_both = phase_distance(blend_phase, walk_phase) + phase_distance(blend_phase, run_phase);
            assert!(
                from_both <= span + 0.02,
                "{foot} a = {a}: walk {walk_phase:.3} run {run_phase:.3} blend {blend_phase:.3}"
            );
        }
    }
}
