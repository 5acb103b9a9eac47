//! The desktop app driven as a person would, through egui_kittest: select by label, change modes, step frames,
//! and check what the panels show.

mod common;

use bonescope::app::{BonescopeApp, Document, Settings};
use bonescope::model::InheritMode;
use common::{asset, settle};
use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};

fn demo_app() -> Harness<'static, BonescopeApp> {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .build_eframe(|_cc| unopened(BonescopeApp::new(Settings::default(), Document::demo())));
    settle(&mut harness);
    harness
}

/// `app` without the first view its analysis would set ([`bonescope::app::Window::opening`]): for the tests that
/// pick their own bone and time, as a user may before the analysis lands (the opening has tests of its own).
fn unopened(mut app: BonescopeApp) -> BonescopeApp {
    app.window.opening = false;
    app
}

fn bone(harness: &Harness<'static, BonescopeApp>, name: &str) -> usize {
    harness.state().session.doc.rig.skeleton.find(name).unwrap()
}

#[test]
fn opens_on_the_demo_rig_with_every_panel() {
    let harness = demo_app();
    for label in ["Skeleton", "Inspector", "Play", "time bar", "viewport"] {
        harness.get_by_label(label);
    }
    for combo in ["Animation", "Inherit scale", "Ghost"] {
        harness.get_by_role_and_label(Role::ComboBox, combo);
    }
    // The demo's bones are listed.
    for name in ["shoulder", "upper_arm", "forearm", "hand"] {
        harness.get_by_label(name);
    }
}

#[test]
fn selecting_a_bone_shows_it_in_the_inspector_with_its_findings() {
    let mut harness = demo_app();
    harness.state_mut().window.time = 0.5;
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let forearm = bone(&harness, "forearm");
    assert_eq!(harness.state().window.selection, vec![forearm]);
    harness.get_by_label_contains("inherit full");
    // At 0.5 s the upper arm is stretched to 1.6× and the forearm bent: under full inheritance it shears.
    harness.get_by_label("findings: stretched (shear)");
    harness.get_by_label("Copy as JSON");
}

#[test]
fn changing_every_bone_to_segment_compensate_removes_the_shear() {
    let mut harness = demo_app();
    harness.state_mut().window.time = 0.5;
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    harness.get_by_role_and_label(Role::ComboBox, "Inherit scale").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "segment-compensate").click();
    settle(&mut harness);
    let app = harness.state();
    assert!(app.session.doc.modes().iter().all(|&m| m == InheritMode::SegmentCompensate));
    harness.get_by_label("findings: none");
    // The whole-clip analysis agrees: nothing is stretched any more.
    assert!(app.analysis().unwrap().scan.bones.iter().all(|b| !b.stretched()));
}

/// The demo in a laptop's window, 1280×800.
fn laptop_demo() -> Harness<'static, BonescopeApp> {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(|_cc| unopened(BonescopeApp::new(Settings::default(), Document::demo())));
    settle(&mut harness);
    harness
}

#[test]
fn every_inherit_scale_choice_is_in_view_at_a_laptops_size() {
    let mut harness = laptop_demo();
    harness.get_by_role_and_label(Role::ComboBox, "Inherit scale").click();
    harness.run();
    // The last choice is clicked where it is drawn, no scrolling first.
    harness.get_by_role_and_label(Role::Button, "blender-none-legacy").click();
    settle(&mut harness);
    assert!(harness.state().session.doc.modes().iter().all(|&m| m == InheritMode::BlenderNoneLegacy));
}

#[test]
fn the_plot_controls_and_the_top_bar_hold_still_whatever_is_chosen() {
    use bonescope::app::Ghost;
    use bonescope::model::ModeChoice;
    let mut rig = bonescope::import::demo_rig();
    rig.clips[1].name = Some("a take named after its studio's whole folder path, as exporters do".into());
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), Document::new(None, rig))));
    settle(&mut harness);
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let places = |harness: &Harness<'static, BonescopeApp>| {
        let combo = |label| harness.get_by_role_and_label(Role::ComboBox, label).rect();
        [harness.get_by_label("Reset view").rect(), harness.get_by_label("ghost").rect(), combo("Inherit scale")]
    };
    let before = places(&harness);
    harness.get_by_role_and_label(Role::Button, "shear°").click();
    settle(&mut harness);
    assert_eq!(places(&harness), before, "a component with no rotation format");
    harness.state_mut().session.doc.ghost = Some(Ghost::Modes(ModeChoice::Mode(InheritMode::SegmentCompensate)));
    settle(&mut harness);
    assert_eq!(places(&harness), before, "a ghost to show");
    for clip in [Some(1), None] {
        harness.state_mut().session.doc.set_clip(clip).unwrap();
        settle(&mut harness);
        assert_eq!(places(&harness), before, "clip {clip:?}, a name of another length");
    }
}

#[test]
fn several_components_stack_and_the_column_says_it_scrolls() {
    let mut harness = laptop_demo();
    harness.state_mut().window.time = 0.5;
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    harness.get_by_role_and_label(Role::Button, "scale k").click();
    harness.step();
    for added in ["shear°", "translation"] {
        harness.get_by_role_and_label(Role::Button, added).click_modifiers(egui::Modifiers::COMMAND);
        harness.step();
    }
    settle(&mut harness);
    // Each curve says whose component it is; three plots do not fit 1280×800's plot panel, and it says so.
    for curve in ["forearm translation x", "forearm scale k z", "forearm shear°"] {
        harness.get_by_label(curve);
    }
    harness.get_by_label("3 plots: the bar at the right scrolls to the rest");
    // Ctrl-click takes one away again; a plain click shows that one alone.
    harness.get_by_role_and_label(Role::Button, "translation").click_modifiers(egui::Modifiers::COMMAND);
    settle(&mut harness);
    assert!(harness.query_by_label("forearm translation x").is_none());
    harness.get_by_role_and_label(Role::Button, "shear°").click();
    settle(&mut harness);
    harness.get_by_label("forearm shear°");
    assert!(harness.query_by_label("forearm scale k z").is_none());
    // The rest pose has no time to plot over: the panel says where its values are instead of a −0.4…0.4 s axis.
    harness.state_mut().session.doc.set_clip(None).unwrap();
    settle(&mut harness);
    harness.get_by_label("One pose, no time to plot it over: the Inspector lists its values.");
}

#[test]
fn arrow_keys_step_one_frame_and_space_plays() {
    let mut harness = demo_app();
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    assert!((harness.state().window.time - 2.0 / 30.0).abs() < 1e-12);
    harness.key_press(egui::Key::ArrowLeft);
    harness.run();
    assert!((harness.state().window.time - 1.0 / 30.0).abs() < 1e-12);
    harness.key_press(egui::Key::Space);
    harness.step();
    assert!(harness.state().window.playing);
    harness.get_by_label("Pause").click();
    harness.run();
    assert!(!harness.state().window.playing);
}

#[test]
fn a_file_that_fails_to_load_keeps_the_document_and_says_why() {
    let mut harness = demo_app();
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.glb");
    std::fs::write(&broken, b"glTF\x02\x00\x00\x00").unwrap();
    harness.state_mut().open(&broken);
    harness.run();
    assert!(harness.state().session.doc.path.is_none(), "still the demo");
    // The file's name first, then what is wrong with it.
    harness.get_by_label("broken.glb");
    harness.get_by_label_contains("broken.glb:");
}

#[test]
fn the_timeline_strip_and_plots_follow_the_analysis() {
    let mut harness = demo_app();
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let app = harness.state();
    let analysis = app.analysis().expect("analysis for the current state");
    let forearm = bone(&harness, "forearm");
    let plotted = app.curves().expect("curves for the selection");
    let curves = plotted.curves_of(forearm).expect("curves of the plotted bone");
    assert_eq!(plotted.times, analysis.times, "the curves and the summary share their samples");
    assert_eq!(curves.model.len(), analysis.times.len());
    assert_eq!(curves.ghost_model.len(), analysis.times.len(), "the demo opens with a ghost");
    // Stretched while the upper arm is scaled, not at t = 0.
    assert!(!analysis.stretched_at(forearm, 0));
    assert!((0..analysis.times.len()).any(|s| analysis.stretched_at(forearm, s)));
}

/// Shows the Layers panel, opens its Blend section and ticks "blend a second clip".
fn blend_a_second_clip(harness: &mut Harness<'static, BonescopeApp>) {
    harness.get_by_role_and_label(Role::Button, "Layers").click();
    settle(harness);
    harness.get_by_label("Blend").click();
    settle(harness);
    harness.get_by_label("blend a second clip").click();
    settle(harness);
}

#[test]
fn the_layers_panel_turns_on_a_synced_blend_and_the_timeline_follows_its_cycle() {
    let mut harness = demo_app();
    blend_a_second_clip(&mut harness);
    let doc = &harness.state().session.doc;
    let blend = doc.layers().blend.expect("the checkbox turned the blend on");
    // The demo's second clip ("bend"), half way, synced: the cycle is (T2 − T1)·a + T1.
    assert_eq!((blend.clip, blend.weight, blend.sync), (1, 0.5, true));
    let (t1, t2) = (doc.rig.clips[0].span().length(), doc.rig.clips[1].span().length());
    let cycle = (t2 - t1) * 0.5 + t1;
    let timeline = doc.span().length();
    assert!((timeline - cycle).abs() < 1e-12, "timeline {timeline} s, cycle {cycle} s");
    harness.get_by_label(&format!("cycle (T2 − T1)·a + T1 = {cycle:.4} s"));
    // Turning it off again restores the clip's own length.
    harness.get_by_label("blend a second clip").click();
    settle(&mut harness);
    assert!(harness.state().session.doc.layers().is_empty());
    assert_eq!(harness.state().session.doc.span().length(), t1);
}

#[test]
fn pinning_a_bone_holds_its_model_rotation_while_the_clip_plays() {
    let mut harness = demo_app();
    harness.state_mut().settings.show(&bonescope::app::Pane::LAYERS, true);
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let forearm = bone(&harness, "forearm");
    // The target's model rotation: the chain of local rotations from the root (scale plays no part).
    let rotation_at = |harness: &Harness<'static, BonescopeApp>, time: f64| {
        let doc = &harness.state().session.doc;
        let local = doc.evaluation().pose_at(time).local;
        let skeleton = &doc.rig.skeleton;
        let mut rotation = local[forearm].rotation;
        let mut at = skeleton.parent(forearm);
        while let Some(parent) = at {
            rotation = local[parent].rotation * rotation;
            at = skeleton.parent(parent);
        }
        rotation
    };
    let unpinned = [0.25, 0.5, 1.0].map(|t| rotation_at(&harness, t));
    harness.get_by_label("World-space targets").click();
    settle(&mut harness);
    harness.get_by_label("Pin forearm where it is now").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.layers().targets.len(), 1);
    let pinned = rotation_at(&harness, 0.0);
    for (time, free) in [0.25, 0.5, 1.0].into_iter().zip(unpinned) {
        // Without the pin the forearm turns with the bending arm; pinned, it keeps the rotation it had at 0 s.
        assert!(free.angle_between(pinned) > 0.05, "the clip moves the forearm at {time} s");
        let held = rotation_at(&harness, time);
        assert!(held.angle_between(pinned) < 1e-9, "at {time} s: {held:?} vs {pinned:?}");
    }
}

/// The app on `doc` with the Layers panel open, settled.
fn layers_app(doc: Document) -> Harness<'static, BonescopeApp> {
    let settings = Settings::default().showing(&bonescope::app::Pane::LAYERS, true);
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(settings, doc)));
    settle(&mut harness);
    harness
}

#[test]
fn the_bind_pose_section_warns_of_a_broken_skin_and_notes_a_stored_pose() {
    // The demo with the forearm's bind alone moved 3 cm up: the hand, bound where it was, is left behind by it.
    let mut rig = bonescope::import::demo_rig();
    rig.skins[0].inverse_bind[1] = glam::DMat4::from_translation(glam::DVec3::new(1.0, 1.53, 0.0)).inverse();
    let harness = layers_app(Document::new(None, rig));
    harness.get_by_label_contains("1 joint's bind matrix disagrees with the joints around: the skin is broken there");
    assert!(harness.query_by_label_contains("stored pose").is_none());
    // Blender's FBX stores its current frame, the forearm turned 20° from its bind: a note, not a warning.
    let harness = layers_app(Document::new(
        Some(asset("blender/stretchy_full.fbx")),
        common::load_asset("blender/stretchy_full.fbx"),
    ));
    harness
        .get_by_label_contains("note: the stored pose is not the bind pose: 1 joint (forearm) is posed up to 20.00°");
    assert!(harness.query_by_label_contains("disagree").is_none());
    assert!(harness.query_by_label_contains("agree with the rest pose").is_none());
    // The check reads the clip as authored: a layer edit (the clip weight) keeps its result on screen, no new check.
    let mut harness = harness;
    let layers = bonescope::eval::Layers { bind_weight: 0.5, ..Default::default() };
    harness.state_mut().session.doc.set_layers(&layers).unwrap();
    harness.step();
    harness.get_by_label_contains("note: the stored pose is not the bind pose");
    assert!(harness.query_by_label_contains("checking the bind matrices").is_none());
}

#[test]
fn the_storage_report_is_measured_off_the_ui_thread_and_shown() {
    let mut harness = demo_app();
    harness.state_mut().settings.show(&bonescope::app::Pane::LAYERS, true);
    settle(&mut harness);
    harness.get_by_label("Stretch-quaternion storage").click();
    settle(&mut harness);
    harness.get_by_label("Measure the clip").click();
    // The report arrives from a worker thread; the panel shows progress meanwhile.
    let started = std::time::Instant::now();
    while harness.query_by_label_contains("frames × 4 bones").is_none() {
        assert!(started.elapsed().as_secs() < 20, "no storage report after 20 s");
        harness.step();
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // Under full inheritance the demo's forearm shear is rebuilt by the chain: no bone needs the stretch channel.
    harness.get_by_label_contains("marked: 0");
    harness.get_by_label("TRS + stretch");
    harness.get_by_label("TRS only");
}

#[test]
fn the_skinning_method_is_chosen_in_the_viewport_toolbar() {
    let mut harness = demo_app();
    assert_eq!(harness.state().settings.scene.skinning, bonescope::eval::SkinningMethod::AsFile);
    harness.get_by_role_and_label(Role::ComboBox, "Skinning").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "dual quaternion").click();
    settle(&mut harness);
    assert_eq!(harness.state().settings.scene.skinning, bonescope::eval::SkinningMethod::DualQuaternion);
}

#[test]
fn a_ten_million_frame_take_opens_and_its_analysis_finishes() {
    // Maya's long-keyframe test: 41 keys over ±166,666 s at 30 fps (10 million frames), sampled at its keys.
    let path = asset("fbx-ufbx-corpus/maya_long_keyframes_7700_ascii.fbx");
    let rig = bonescope::import::load(&path).unwrap();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), Document::new(Some(path), rig))));
    harness.get_by_label("pCube1").click();
    settle(&mut harness);
    assert!(harness.state().session.doc.clip().unwrap().span().length() > 333_000.0);
    harness.get_by_label("time bar");
    harness.get_by_label("Next frame").click();
    settle(&mut harness);
    // The take starts where Maya stored it, far before 0: one frame after that.
    let (time, start) = (harness.state().window.time, harness.state().session.doc.span().start);
    assert!(start < -166_000.0 && (time - start - 1.0 / 30.0).abs() < 1e-9, "one frame on from {start}: {time}");
}

#[test]
fn declared_modes_are_one_click_away_after_any_edit() {
    let mut harness = demo_app();
    let declared = harness.state().session.doc.rig.skeleton.declared_modes();
    harness.get_by_role_and_label(Role::ComboBox, "Inherit scale").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "segment-compensate").click();
    settle(&mut harness);
    assert_ne!(harness.state().session.doc.modes(), declared);
    harness.get_by_role_and_label(Role::ComboBox, "Inherit scale").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "declared").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.modes(), declared);
}

#[test]
fn the_outliner_menu_selects_its_row_and_sets_declared_modes() {
    let mut harness = demo_app();
    let hand = bone(&harness, "hand");
    harness.get_by_label("hand").click_secondary();
    harness.run();
    assert_eq!(harness.state().window.selection, vec![hand], "right-clicking a row selects it");
    harness.get_by_label("Set mode of this bone").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "componentwise").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.modes()[hand], InheritMode::Componentwise);
    // The Inspector now names the bone too: the outliner's row is the button.
    harness.get_by_role_and_label(Role::Button, "hand").click_secondary();
    harness.run();
    harness.get_by_label("Set mode of this bone").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "declared").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.modes()[hand], harness.state().session.doc.rig.skeleton.bone(hand).inherit);
}

fn asset_app(path: &str) -> Harness<'static, BonescopeApp> {
    let doc = Document::load(&asset(path)).unwrap();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), doc)));
    settle(&mut harness);
    harness
}

#[test]
fn frames_are_the_clips_own_and_whole() {
    // CMU mocap at 120 Hz: one press steps one source frame, and the rate is shown.
    let mut harness = asset_app("bvh/cmu_12_01_walk.bvh");
    assert!(
        (harness.state().session.doc.frame_rate() - 120.0).abs() < 0.01,
        "{}",
        harness.state().session.doc.frame_rate()
    );
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    assert!((harness.state().window.time - 0.008_333_3).abs() < 1e-9, "{}", harness.state().window.time);
    // From between two frames (a click on the time bar), a step lands on the next whole frame.
    harness.state_mut().window.time = 17.98 / 120.005;
    harness.get_by_label("Next frame").click();
    harness.run();
    let frames = harness.state().window.time * harness.state().session.doc.frame_rate();
    assert!((frames - 18.0).abs() < 1e-9, "frame {frames}");
    // End and Home go to the ends; Play at the end without Loop starts again.
    harness.key_press(egui::Key::End);
    harness.run();
    assert_eq!(harness.state().window.time, harness.state().session.doc.span().end);
    harness.get_by_label("Loop").click();
    harness.run();
    harness.get_by_label("Play").click();
    harness.step();
    assert!(harness.state().window.playing && harness.state().window.time < 0.1, "{}", harness.state().window.time);
    harness.key_press(egui::Key::Space);
    harness.run();
    assert!(!harness.state().window.playing);
    harness.key_press(egui::Key::Home);
    harness.run();
    assert_eq!(harness.state().window.time, 0.0);
}

/// Blender's glTF export, on its own clock: both clips start at frame 1 (1/30 s); `squash_stretch` (opened) plays
/// 2 s, to frame 61, `wave` 1.33 s.
fn blender_app() -> Harness<'static, BonescopeApp> {
    asset_app("blender/stretchy_full.glb")
}

/// The current time in frames of the document's rate.
fn frame(harness: &Harness<'static, BonescopeApp>) -> f64 {
    harness.state().window.time * harness.state().session.doc.frame_rate()
}

#[test]
fn a_clip_from_frame_1_opens_there_and_steps_to_frame_2() {
    let mut harness = blender_app();
    let span = harness.state().session.doc.span();
    assert!((span.start - 1.0 / 30.0).abs() < 1e-7, "{span:?}");
    assert_eq!(harness.state().window.time, span.start, "the playhead at the clip's start, not at 0");
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    assert!((frame(&harness) - 2.0).abs() < 1e-9, "frame {}", frame(&harness));
    // Back, and no further than the first frame.
    for _ in 0..2 {
        harness.get_by_label("Previous frame").click();
        harness.run();
    }
    assert_eq!(harness.state().window.time, span.start);
}

#[test]
fn home_and_end_go_to_the_ends_of_the_clips_span() {
    let mut harness = blender_app();
    harness.state_mut().window.time = 1.0;
    harness.key_press(egui::Key::End);
    harness.run();
    let span = harness.state().session.doc.span();
    assert!((span.end - 61.0 / 30.0).abs() < 1e-7, "{span:?}");
    assert_eq!(harness.state().window.time, span.end);
    harness.key_press(egui::Key::Home);
    harness.run();
    assert_eq!(harness.state().window.time, span.start, "frame 1, not 0");
}

#[test]
fn a_loop_goes_round_within_the_clips_span() {
    // A mocked clock, as in `a_pause_or_an_idle_spell_never_counts_as_playing`.
    let mut harness = blender_app();
    let at = |harness: &mut Harness<'static, BonescopeApp>, t: f64| {
        harness.input_mut().time = Some(t);
        harness.step();
    };
    let span = harness.state().session.doc.span();
    assert!(harness.state().settings.looping);
    at(&mut harness, 100.0);
    harness.state_mut().window.time = span.end - 0.05;
    harness.state_mut().toggle_play();
    at(&mut harness, 100.0);
    at(&mut harness, 100.1);
    // 0.05 s past the end goes on 0.05 s after the clip's start, not 0.05 s after 0.
    let time = harness.state().window.time;
    assert!(harness.state().window.playing && (time - (span.start + 0.05)).abs() < 1e-9, "{time} in {span:?}");
}

#[test]
fn another_clip_holds_the_time_within_its_own_span() {
    let mut harness = blender_app();
    harness.state_mut().window.time = 1.8;
    harness.get_by_role_and_label(Role::ComboBox, "Animation").click();
    harness.run();
    harness.get_by_label("wave (1.33 s)").click();
    settle(&mut harness);
    let doc = &harness.state().session.doc;
    assert_eq!(doc.clip().map(|c| c.label()).as_deref(), Some("wave"));
    assert_eq!(harness.state().window.time, doc.span().end, "1.8 s is past its end");
}

#[test]
fn the_controls_after_the_time_hold_still_as_it_changes() {
    let mut harness = blender_app();
    let length = harness.get_by_label("of 2.000 s").rect();
    // Between two frames ("frame 1.5") and at the last ("frame 61"): the field keeps its width.
    for time in [1.5 / 30.0, harness.state().session.doc.span().end] {
        harness.state_mut().window.time = time;
        harness.run();
        assert_eq!(harness.get_by_label("of 2.000 s").rect(), length, "at {time} s");
    }
}

#[test]
fn the_time_readout_takes_a_typed_time() {
    let mut harness = demo_app();
    harness.get_by_role_and_label(Role::SpinButton, "current time").click();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_role_and_label(Role::SpinButton, "current time").type_text("1.25");
    harness.key_press(egui::Key::Enter);
    harness.run();
    assert!((harness.state().window.time - 1.25).abs() < 1e-12, "{}", harness.state().window.time);
}

#[test]
fn clicking_a_bones_worst_shear_goes_there() {
    let mut harness = demo_app();
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    // The forearm and the hand both peak at 38.1°: the hand's label is the second.
    harness.get_all_by_label_contains("max 38.1°").nth(1).unwrap().click();
    settle(&mut harness);
    let hand = bone(&harness, "hand");
    assert_eq!(harness.state().window.selection, vec![hand]);
    let worst = harness.state().analysis().unwrap().scan.bones[hand].worst_shear_time;
    assert_eq!(harness.state().window.time, worst);
}

#[test]
fn playback_follows_the_wall_clock_when_frames_are_slow() {
    // Frames 0.25 s apart (a heavy scene): the clip advances by the time that passed, skipping frames, instead of
    // playing in slow motion.
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .with_step_dt(0.25)
        .build_eframe(|_cc| unopened(BonescopeApp::new(Settings::default(), Document::demo())));
    settle(&mut harness);
    harness.key_press(egui::Key::Space);
    harness.step();
    let start = harness.state().window.time;
    harness.step();
    harness.step();
    assert!((harness.state().window.time - start - 0.5).abs() < 1e-6, "{} after {start}", harness.state().window.time);
}

#[test]
fn thresholds_are_edited_in_the_view_menu_and_decide_the_flags() {
    let mut harness = demo_app();
    assert!(harness.state().analysis().unwrap().scan.bones.iter().any(|b| b.stretched()));
    harness.get_by_label("View").click();
    harness.run();
    harness.get_by_label("Thresholds").click();
    harness.run();
    let field = harness.get_by_role_and_label(Role::SpinButton, "min shear angle");
    field.click();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_role_and_label(Role::SpinButton, "min shear angle").type_text("60");
    harness.key_press(egui::Key::Enter);
    settle(&mut harness);
    assert_eq!(harness.state().settings.tolerances.min_shear_deg, 60.0);
    // The demo's worst shear is 38.1°: nothing is flagged any more, in the whole-clip analysis either.
    assert!(harness.state().analysis().unwrap().scan.bones.iter().all(|b| !b.stretched()));
}

#[test]
fn selecting_a_bone_does_not_move_the_viewport() {
    // At 1000×700 with the Layers panel open, the Inspector's matrices are wider than its panel: they scroll, the
    // panels keep their widths and the viewport stays where it was.
    let settings = Settings::default().showing(&bonescope::app::Pane::LAYERS, true);
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1000.0, 700.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(settings, Document::demo())));
    settle(&mut harness);
    let before = harness.get_by_label("viewport").rect();
    assert!(before.width() >= 0.4 * 1000.0, "the viewport keeps 40 % of the window: {before:?}");
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    assert_eq!(harness.get_by_label("viewport").rect(), before);
}

#[test]
fn f_frames_a_selected_bone_with_room_around_it() {
    let mut harness = demo_app();
    harness.get_by_label("hand").click();
    settle(&mut harness);
    harness.get_by_label("viewport").hover();
    harness.run();
    harness.key_press(egui::Key::F);
    harness.run();
    // A leaf bone is one point: framed with a few gizmo sizes around it (the demo's are 0.4 long), not zoomed
    // into the joint.
    let camera = harness.state().settings.camera;
    assert!(camera.distance > 0.5, "distance {}", camera.distance);
}

#[test]
fn copy_as_json_is_what_inspect_prints_and_says_so() {
    let path = asset("blender/stretchy_full.glb");
    let mut harness = asset_app("blender/stretchy_full.glb");
    harness.state_mut().window.time = 0.5;
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    harness.get_by_label("Copy as JSON").click();
    harness.step();
    let copied = harness
        .output()
        .platform_output
        .commands
        .iter()
        .find_map(|c| match c {
            egui::OutputCommand::CopyText(text) => Some(text.clone()),
            _ => None,
        })
        .expect("copied");
    harness.run();
    harness.get_by_label("Copied");
    let cli = std::process::Command::new(env!("CARGO_BIN_EXE_bonescope"))
        .args(["inspect", &path.display().to_string(), "--time", "0.5", "--format", "json"])
        .output()
        .unwrap();
    assert!(cli.status.success());
    let parse = |text: &str| serde_json::from_str::<serde_json::Value>(text).unwrap();
    assert_eq!(parse(&copied), parse(&String::from_utf8(cli.stdout).unwrap()));
}

#[test]
fn a_broken_file_is_remembered_watched_and_opens_once_fixed() {
    let mut harness = demo_app();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("character.bvh");
    std::fs::write(&file, b"HIERARCHY\nROOT hips\n{").unwrap();
    harness.state_mut().open(&file);
    harness.state_mut().open(&file);
    harness.run();
    assert!(harness.state().session.doc.path.is_none(), "still the demo");
    assert_eq!(harness.state().settings.recent.first(), Some(&file), "listed in the recent files");
    let errors = harness.state().errors();
    assert_eq!((errors.len(), errors[0].1), (1, 2), "the same error twice is one message: {errors:?}");
    // Fixed on disk: the watcher opens it, and the error goes.
    let good = std::fs::read(asset("bvh/bvh_test2.bvh")).unwrap();
    std::fs::write(&file, good).unwrap();
    for _ in 0..100 {
        std::thread::sleep(std::time::Duration::from_millis(20));
        harness.step();
        if harness.state().session.doc.path.is_some() {
            break;
        }
    }
    assert_eq!(harness.state().session.doc.path.as_deref(), Some(file.as_path()));
    assert!(harness.state().errors().is_empty(), "{:?}", harness.state().errors());
}

#[test]
fn a_message_under_the_pointer_holds_still() {
    let mut harness = demo_app();
    let path = asset("bvh/bvh_test2.bvh");
    harness.state_mut().open(&path);
    harness.run();
    harness.get_by_label_contains("opened").hover();
    // Five seconds (20 steps of 0.25 s) with the pointer on it: it does not fade, so nothing moves under a click.
    for _ in 0..20 {
        harness.step();
    }
    harness.get_by_label_contains("opened");
    harness.get_by_label("viewport").hover();
    for _ in 0..20 {
        harness.step();
    }
    assert!(harness.query_by_label_contains("opened").is_none(), "faded once the pointer left");
}

#[test]
fn the_outliner_scrolls_to_a_bone_picked_elsewhere() {
    let mut harness = asset_app("bvh/cmu_12_01_walk.bvh");
    let skeleton = &harness.state().session.doc.rig.skeleton;
    let (last, name) = (skeleton.len() - 1, skeleton.bone(skeleton.len() - 1).name.clone());
    assert!(harness.query_by_label(&name).is_none(), "{name} starts below the fold");
    // As a click in the viewport does.
    harness.state_mut().window.selection = vec![last];
    harness.step();
    harness.state_mut().settle();
    // The list scrolls smoothly: a few frames.
    harness.run_steps(12);
    // The outliner's row (the Inspector names the bone too).
    harness.get_by_role_and_label(Role::Button, &name);
}

#[test]
fn file_open_without_a_desktop_dialog_uses_the_apps_own_browser() {
    let mut harness = demo_app();
    harness.state_mut().window.dialogs.native = bonescope::app::NativeDialog::Unavailable;
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label("Open…").click();
    harness.run();
    harness.get_by_label_contains("no desktop file dialog here");
    harness.get_by_label("Open a file");
    // Type a folder: the browser enters it and lists its animation files; click one to open it.
    let folder = asset("bvh");
    let field = harness.get_by_label("Path");
    field.click();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("Path").type_text(&folder.display().to_string());
    harness.key_press(egui::Key::Enter);
    harness.run();
    harness.get_by_label("cmu_12_01_walk.bvh").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.path.as_deref(), Some(folder.join("cmu_12_01_walk.bvh").as_path()));
    assert!(harness.query_by_label("Open a file").is_none(), "the browser closes once a file is chosen");
}

#[test]
fn the_wheel_zooms_the_plots_time_about_the_pointer() {
    let mut harness = demo_app();
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let ctx = harness.ctx.clone();
    let memory = || egui_plot::PlotMemory::load(&ctx, bonescope::app::plot_id(0)).expect("the plot is shown");
    let (before, frame) = (*memory().bounds(), *memory().transform().frame());
    // The pointer a quarter of the way in, one wheel notch up.
    let at = frame.lerp_inside(egui::vec2(0.25, 0.5));
    let x_at = memory().transform().value_from_position(at).x;
    harness.event(egui::Event::PointerMoved(at));
    harness.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 50.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers: egui::Modifiers::NONE,
    });
    harness.run_steps(10);
    let after = *memory().bounds();
    let (width_before, width_after) = (before.width(), after.width());
    assert!(width_after < 0.95 * width_before, "zoomed in: {width_before} → {width_after}");
    // About the pointer: the time under it stays where it was on screen.
    let still = memory().transform().value_from_position(at).x;
    assert!((still - x_at).abs() < 0.02 * width_before, "{x_at} → {still}");
    assert_eq!(harness.state().window.time, 0.0, "the wheel does not seek");
}

/// The file at `source` baked with every bone under `mode` by `strategy`, written to `out`.
fn bake(source: &std::path::Path, mode: InheritMode, strategy: bonescope::bake::Strategy, out: &std::path::Path) {
    let rig = bonescope::import::load(source).unwrap();
    let source = bonescope::eval::Evaluation::new(&rig, None, &vec![mode; rig.skeleton.len()]).unwrap();
    let request = bonescope::bake::Request::every_clip(&source, None, strategy, bonescope::bake::DEFAULT_TOLERANCE);
    bonescope::bake::save(out, &bonescope::bake::bake(&request).bytes).unwrap();
}

/// Maya's mixed-inheritance file baked as the closest TRS under unscaled-parent, written to `folder`.
fn maya_trs_bake(folder: &std::path::Path) -> std::path::PathBuf {
    let path = asset("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx");
    let out = folder.join("maya_trs.glb");
    bake(&path, InheritMode::UnscaledParent, bonescope::bake::Strategy::Trs, &out);
    out
}

#[test]
fn a_compared_file_is_the_ghost_its_curves_are_dashed_and_its_differences_badged() {
    let folder = tempfile::tempdir().unwrap();
    let baked = maya_trs_bake(folder.path());
    let mut harness = asset_app("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx");
    let unscaled = bonescope::model::ModeChoice::Mode(InheritMode::UnscaledParent);
    harness.state_mut().session.doc.set_mode(0, bonescope::app::ModeScope::All, unscaled);
    harness.state_mut().compare(&baked);
    settle(&mut harness);
    let doc = &harness.state().session.doc;
    assert_eq!(doc.ghost, Some(bonescope::app::Ghost::Compared));
    assert_eq!(doc.compared.as_ref().map(|c| c.path.clone()), Some(baked.clone()));
    harness.get_by_label_contains("comparing with");
    // The TRS bake drops the stretch of `Mid` (it needed a helper): `Mid` and what hangs below it differ, the root
    // does not.
    let differences = harness.state().differences().expect("differences over the clip").clone();
    let mid = bone(&harness, "Mid");
    assert!(differences.bones[mid].unwrap() > 1e-4, "{:?}", differences.bones);
    assert!(differences.bones[0].unwrap() < 1e-6, "{:?}", differences.bones);
    assert!(harness.query_all_by_label_contains("Δ ").count() >= 2, "Mid and what hangs below it are badged");
    // Plotting a bone with the ghost on shows the compared file's curves beside the document's.
    harness.get_by_label("Left_Tip").click();
    settle(&mut harness);
    harness.get_by_role_and_label(Role::CheckBox, "ghost").click();
    settle(&mut harness);
    let compared = harness.query_all_by_label_contains("(compared)").count();
    let all = harness.query_all_by_label_contains("Left_Tip ").count();
    assert!(compared > 0 && 2 * compared == all, "one compared curve beside each of the bone's: {compared} of {all}");
    // Stop comparing: the ghost goes with it.
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label_contains("Stop comparing with").click();
    settle(&mut harness);
    assert!(harness.state().session.doc.compared.is_none() && harness.state().session.doc.ghost.is_none());
}

#[test]
fn compare_with_asks_for_a_file_and_a_change_on_disk_reloads_it() {
    let folder = tempfile::tempdir().unwrap();
    let copy = folder.path().join("copy.glb");
    let source = asset("blender/stretchy_full.glb");
    std::fs::copy(&source, &copy).unwrap();
    let mut harness = asset_app("blender/stretchy_full.glb");
    harness.state_mut().window.dialogs.native = bonescope::app::NativeDialog::Unavailable;
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label("Compare with…").click();
    harness.run();
    harness.get_by_label("Compare with a file");
    harness.get_by_label("Path").click();
    harness.run();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    harness.get_by_label("Path").type_text(&folder.path().display().to_string());
    harness.key_press(egui::Key::Enter);
    harness.run();
    harness.get_by_label("copy.glb").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.compared.as_ref().map(|c| c.path.clone()), Some(copy.clone()));
    let differences = &harness.state().differences().unwrap().bones;
    assert!(differences.iter().flatten().all(|&d| d == 0.0), "a file against its copy: {differences:?}");
    // The copy changes on disk (rewritten as the same clip under segment scale compensate): the comparison follows.
    bake(&source, InheritMode::SegmentCompensate, bonescope::bake::Strategy::Exact, &copy);
    for _ in 0..100 {
        std::thread::sleep(std::time::Duration::from_millis(20));
        harness.step();
        if harness.state().differences().is_none() {
            break;
        }
    }
    settle(&mut harness);
    let differences = harness.state().differences().expect("the reloaded file's differences");
    assert!(differences.bones.iter().any(|d| d.is_some_and(|d| d > 1e-3)), "{differences:?}");
    harness.get_by_label_contains("reloaded");
}

/// The app on a shared file in a laptop's window, 1280×800, with the Layers and the Inspector open and `bone`
/// inspected at `time`.
fn laptop_app(path: &str, bone: &str, time: f64) -> Harness<'static, BonescopeApp> {
    let doc = Document::load(&asset(path)).unwrap();
    let index = doc.rig.skeleton.find(bone).unwrap();
    let settings = Settings::default().showing(&bonescope::app::Pane::LAYERS, true);
    // Scrolling the outliner to a bone deep in a long list settles over a few more frames than the default allows.
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .with_max_steps(12)
        .build_eframe(move |_cc| unopened(BonescopeApp::new(settings, doc)));
    harness.state_mut().window.time = time;
    harness.state_mut().window.selection = vec![index];
    settle(&mut harness);
    harness
}

/// Every label and button that starts inside a panel ends inside it: no number or name is cut at the panel's
/// right edge (text that does not fit wraps, names shorten in the middle).
fn assert_nothing_cut(harness: &Harness<'static, BonescopeApp>) {
    use bonescope::app::Pane;
    let window = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0));
    for pane in ["Skeleton", "Inspector", "Layers"].map(Pane::named) {
        let rect = harness.state().pane_rect(&pane).unwrap_or_else(|| panic!("{pane:?} is shown"));
        assert!(rect.width() >= 200.0, "{pane:?} is {} wide", rect.width());
        let nodes = harness.query_all_by_role(Role::Label).chain(harness.query_all_by_role(Role::Button));
        let mut checked = 0;
        for node in nodes {
            let r = node.rect();
            let inside = rect.contains(egui::pos2(r.left() + 1.0, r.center().y)) && window.contains(r.center());
            if inside {
                checked += 1;
                assert!(
                    r.right() <= rect.right() + 1.0,
                    "{pane:?}: {node:?} ends at {} past {}",
                    r.right(),
                    rect.right()
                );
            }
        }
        assert!(checked > 5, "{pane:?}: only {checked} labels");
    }
}

#[test]
fn at_a_laptops_size_every_number_and_name_is_whole() {
    let harness = laptop_app("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx", "Left_Tip", 0.5);
    assert_nothing_cut(&harness);
    // Both matrices whole, four columns each, within the Inspector's width (the column scrolls below them).
    let inspector = harness.state().pane_rect(&bonescope::app::Pane::named("Inspector")).unwrap();
    let numbers = harness
        .query_all_by_role(Role::Label)
        .filter(|n| n.value().is_some_and(|l| l.trim().parse::<f64>().is_ok()))
        .filter(|n| inspector.x_range().contains(n.rect().left()) && n.rect().right() <= inspector.right())
        .filter(|n| inspector.y_range().contains(n.rect().top()))
        .count();
    assert!(numbers >= 2 * 16, "{numbers} numbers in the Inspector");
    let harness = laptop_app("fbx-ufbx-corpus/maya_human_ik_6100_binary.fbx", "Character1_RightHandMiddle3", 0.0);
    assert_nothing_cut(&harness);
}

#[test]
fn a_pause_or_an_idle_spell_never_counts_as_playing() {
    // A mocked clock: the frame's input time is set by hand.
    let mut harness = asset_app("bvh/cmu_12_01_walk.bvh");
    let at = |harness: &mut Harness<'static, BonescopeApp>, t: f64| {
        harness.input_mut().time = Some(t);
        harness.step();
    };
    at(&mut harness, 100.0);
    harness.state_mut().window.time = 0.0;
    // Idle 3 s, then Play: the first frame adds nothing, the next ones their frame times.
    at(&mut harness, 103.0);
    harness.state_mut().toggle_play();
    at(&mut harness, 103.0);
    at(&mut harness, 103.05);
    assert!((harness.state().window.time - 0.05).abs() < 1e-9, "{}", harness.state().window.time);
    harness.state_mut().toggle_play();
    at(&mut harness, 110.0);
    harness.state_mut().toggle_play();
    at(&mut harness, 110.0);
    assert!(
        (harness.state().window.time - 0.05).abs() < 1e-9,
        "the pause did not count: {}",
        harness.state().window.time
    );
    harness.state_mut().window.playing = false;
    // At the end of a clip without Loop, Play after an idle spell plays from the start.
    let end = harness.state().session.doc.span().end;
    harness.state_mut().settings.looping = false;
    harness.state_mut().window.time = end;
    at(&mut harness, 200.0);
    harness.state_mut().toggle_play();
    at(&mut harness, 200.0);
    at(&mut harness, 200.1);
    assert!(harness.state().window.playing);
    assert!((harness.state().window.time - 0.1).abs() < 1e-9, "{}", harness.state().window.time);
}

#[test]
fn every_key_repeat_of_a_held_arrow_is_a_frame() {
    let mut harness = asset_app("bvh/cmu_12_01_walk.bvh");
    harness.state_mut().window.time = 0.0;
    // A slow frame receives five repeats of →: five frames of the 120 Hz take.
    for _ in 0..5 {
        harness.input_mut().events.push(egui::Event::Key {
            key: egui::Key::ArrowRight,
            physical_key: None,
            pressed: true,
            repeat: true,
            modifiers: egui::Modifiers::NONE,
        });
    }
    harness.step();
    let rate = harness.state().session.doc.frame_rate();
    assert!((harness.state().window.time - 5.0 / rate).abs() < 1e-12, "{}", harness.state().window.time);
}

#[test]
fn frames_are_frames_everywhere_once_chosen() {
    let settings = Settings { time_unit: bonescope::app::TimeUnit::Frames, ..Settings::default() };
    let doc = Document::load(&asset("bvh/cmu_12_01_walk.bvh")).unwrap();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(settings, doc)));
    settle(&mut harness);
    let rate = harness.state().session.doc.frame_rate();
    let frames = (harness.state().session.doc.span().length() * rate).round();
    harness.get_by_label(&format!("of {frames} frames"));
    // A click anywhere on the time bar lands on a whole frame.
    let bar = harness.get_by_label("time bar").rect();
    let at = egui::pos2(bar.left() + 0.377 * bar.width(), bar.center().y);
    harness.event(egui::Event::PointerMoved(at));
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    harness.run();
    assert!(harness.state().window.time > 0.0, "the click moved the time");
    let frame = harness.state().window.time * rate;
    assert!((frame - frame.round()).abs() < 1e-9, "frame {frame}");
}

#[test]
fn messages_stack_in_the_viewport_wrap_and_cover_no_control_nor_the_caption() {
    use bonescope::app::Pane;
    let mut harness = demo_app();
    let dir = tempfile::tempdir().unwrap();
    let long = format!("{}.glb", "a_very_long_file_name_from_a_studio_pipeline_".repeat(3));
    for name in [long.as_str(), "second.glb"] {
        let broken = dir.path().join(name);
        std::fs::write(&broken, b"glTF\x02\x00\x00\x00").unwrap();
        harness.state_mut().open(&broken);
    }
    harness.run();
    let viewport = harness.state().pane_rect(&Pane::VIEWPORT).unwrap();
    let messages = harness.state().notifications_rect().unwrap();
    assert!(viewport.contains_rect(messages), "{messages:?} within {viewport:?}");
    let caption_side = viewport.right() - viewport.width() * bonescope::app::CAPTION_SIDE;
    assert!(messages.right() <= caption_side, "{messages:?} clear of the caption (right of x = {caption_side})");
    // Both whole: each error's text wraps within the stack, and each has its Dismiss.
    assert_eq!(harness.query_all_by_label("Dismiss").count(), 2);
    let texts: Vec<_> =
        harness.query_all_by_role(Role::Label).filter(|n| n.value().is_some_and(|l| l.contains(".glb:"))).collect();
    assert_eq!(texts.len(), 2, "both errors' texts");
    for node in texts {
        assert!(messages.contains_rect(node.rect().shrink(1.0)), "{:?} cut", node.value());
    }
    // The timeline's controls are outside it.
    for label in ["Play", "current time", "time bar"] {
        assert!(!messages.intersects(harness.get_by_label(label).rect()), "{label} covered");
    }
}

#[test]
fn nothing_moves_when_play_turns_to_pause_or_json_is_copied() {
    use bonescope::app::Pane;
    let mut harness = demo_app();
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let before = (harness.get_by_label("Loop").rect(), harness.state().pane_rect(&Pane::LAYERS));
    let inspector = harness.state().pane_rect(&Pane::named("Inspector"));
    harness.get_by_label("Play").click();
    harness.step();
    harness.step();
    assert_eq!(harness.get_by_label("Loop").rect(), before.0, "the controls after Pause stay put");
    harness.get_by_label("Pause").click();
    harness.step();
    harness.get_by_label("Copy as JSON").click();
    harness.step();
    harness.step();
    harness.get_by_label("Copied");
    assert_eq!(harness.state().pane_rect(&Pane::named("Inspector")), inspector);
    assert_eq!(harness.state().pane_rect(&Pane::LAYERS), before.1);
}

#[test]
fn a_narrow_window_keeps_every_toolbar_control_with_a_long_take_name() {
    let mut doc = Document::demo();
    let rig = std::sync::Arc::make_mut(&mut doc.rig);
    rig.clips[0].name = Some("Character1|Take 001|BaseLayer|walk_cycle_final_v12_approved_by_lead".to_owned());
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1000.0, 700.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), doc)));
    settle(&mut harness);
    let layers = harness.get_by_label("Layers").rect();
    assert!(layers.right() <= 1000.0 && layers.bottom() <= 700.0, "{layers:?}");
}

/// The height (largest minus smallest Y) of the document's bones that have a partner in the compared file, in the
/// document's pose at `time` and in the ghost's (the compared file's pose, as drawn).
fn figure_and_ghost_heights(app: &BonescopeApp, time: f64) -> (f64, f64) {
    let doc = &app.session.doc;
    let compared = doc.compared.as_ref().expect("a compared file");
    let (own, other) = (doc.evaluation().pose_at(time), compared.evaluation(doc.setup().clip).pose_at(time));
    let height =
        |ys: Vec<f64>| ys.iter().copied().fold(f64::MIN, f64::max) - ys.iter().copied().fold(f64::MAX, f64::min);
    let paired: Vec<(usize, usize)> =
        compared.bones.iter().enumerate().filter_map(|(a, b)| b.map(|b| (a, b))).collect();
    let figure = height(paired.iter().map(|&(a, _)| own.model.model[a].w_axis.y).collect());
    let ghost = height(paired.iter().map(|&(_, b)| other.model.model[b].w_axis.y).collect());
    (figure, ghost)
}

#[test]
fn a_bvh_compared_in_the_unit_picked_for_it_ghosts_at_the_figures_size() {
    // ProAnimationBank's run is in metres once imported; the CMU walk states no unit. Taken as written its ghost
    // stands about 17 times the runner's height; in CMU's own unit (1/0.45 inch, picked beside the ghost picker)
    // the two subjects stand within a few percent of each other (1.37 m and 1.29 m from toe to head at 0 s).
    let mut harness = asset_app("fbx-proanimationbank/run.fbx");
    harness.state_mut().compare(&asset("bvh/cmu_12_01_walk.bvh"));
    settle(&mut harness);
    let (figure, ghost) = figure_and_ghost_heights(harness.state(), 0.0);
    assert!(ghost / figure > 10.0, "as written: {figure} against {ghost}");
    let before = harness.state().differences().expect("differences").rig_size;
    harness.get_by_role_and_label(Role::ComboBox, "unit of cmu_12_01_walk.bvh").click();
    harness.run();
    harness.get_by_label("CMU mocap units (1/0.45 in)").click();
    settle(&mut harness);
    let (figure, ghost) = figure_and_ghost_heights(harness.state(), 0.0);
    assert!((ghost / figure - 1.0).abs() < 0.15, "in CMU units: {figure} against {ghost}");
    assert_eq!(
        harness.state().session.doc.compared.as_ref().unwrap().units()[1].map(|u| u.in_metres()),
        Some(0.0254 / 0.45)
    );
    // The badges follow the unit: they are fractions of a rig the runner's size, not of a ghost seventeen times it.
    let after = harness.state().differences().expect("differences in the unit picked").rig_size;
    assert!(after < before / 10.0 && (after - figure).abs() < 0.5 * figure, "{before} then {after} ({figure})");
    harness.get_by_role_and_label(Role::ComboBox, "unit of cmu_12_01_walk.bvh");
}

#[test]
fn a_z_up_bvh_compared_says_it_lies_down_and_stands_up_on_the_axis_picked() {
    // Blender's BVH of the stretchy rig is in Blender's Z-up space: beside the rig's glTF it lies on the floor. In a
    // laptop's window, where the top bar's pickers wrap.
    let doc = Document::load(&asset("blender/stretchy_full.glb")).unwrap();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), doc)));
    settle(&mut harness);
    harness.state_mut().compare(&asset("blender/stretchy_full.bvh"));
    settle(&mut harness);
    harness.get_by_role_and_label(Role::ComboBox, "unit of stretchy_full.bvh").click();
    harness.run();
    harness.get_by_label("metres").click();
    settle(&mut harness);
    harness.get_by_label("lies along Z: stretchy_full.glb stands along Y");
    let worst = |harness: &Harness<'static, BonescopeApp>| {
        let differences = harness.state().differences().expect("differences");
        differences.bones.iter().flatten().copied().fold(0.0, f64::max)
    };
    let lying = worst(&harness);
    harness.get_by_role_and_label(Role::ComboBox, "up of stretchy_full.bvh").click();
    harness.run();
    harness.get_by_label("Z").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.compared.as_ref().unwrap().stance.up, bonescope::model::UpAxis::Z);
    assert!(harness.query_by_label_contains("lies along").is_none(), "standing, nothing to say");
    // Standing, the ghost stands where the figure does: what is left is what a BVH cannot store (its scale).
    let (figure, ghost) = figure_and_ghost_heights(harness.state(), 0.0);
    assert!((ghost / figure - 1.0).abs() < 0.05, "{figure} against {ghost}");
    assert!(worst(&harness) < lying / 2.0, "{lying} then {}", worst(&harness));
}

/// The node labelled `label` inside the Inspector (the skeleton's rows name the same bones).
fn in_inspector<'h>(harness: &'h Harness<'static, BonescopeApp>, label: &'h str) -> egui_kittest::Node<'h> {
    in_pane(harness, "Inspector", label)
}

/// The node labelled `label` inside the panel titled `pane`.
fn in_pane<'h>(
    harness: &'h Harness<'static, BonescopeApp>,
    pane: &'static str,
    label: &'h str,
) -> egui_kittest::Node<'h> {
    let rect = harness.state().pane_rect(&bonescope::app::Pane::named(pane)).unwrap();
    let mut nodes = harness.get_all_by_label(label);
    nodes.find(|n| rect.contains(n.rect().center())).unwrap_or_else(|| panic!("no {label} in the {pane}"))
}

/// The demo in a laptop's window with the forearm inspected and its Why? section open, explained.
fn why_forearm() -> Harness<'static, BonescopeApp> {
    let mut harness = laptop_demo();
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    harness.get_by_label("Why?").click();
    settle(&mut harness);
    harness.get_by_label("Fixes, best first");
    harness
}

/// The fixes the library ranks for `bone` of the app's document, as `bonescope explain` ranks them.
fn ranked_fixes(app: &BonescopeApp, bone: usize) -> Vec<bonescope::explain::Fix> {
    let evaluation = app.session.doc.evaluation();
    let options =
        bonescope::analysis::ScanOptions { rate: app.session.doc.analysis_rate(), tolerances: app.settings.tolerances };
    let before = bonescope::analysis::scan_analysis(&evaluation, &options);
    let question = bonescope::explain::Question { bones: Some(&[bone]), ..Default::default() };
    bonescope::explain::explain(&evaluation, &before, question, &options).remove(0).fixes
}

#[test]
fn why_names_the_cause_selects_along_the_chain_and_tries_a_mode() {
    use bonescope::app::Ghost;
    use bonescope::explain::Change;
    use bonescope::model::ModeChoice;
    let mut harness = why_forearm();
    let (forearm, upper_arm) = (bone(&harness, "forearm"), bone(&harness, "upper_arm"));
    // The upper arm's squash under the elbow's turn shears the forearm.
    harness.get_by_label_contains("forearm: upper_arm's scale (");
    harness.get_by_label("main");
    // A bone of the chain is a click away: it is selected (highlighted in the viewport, its axes drawn, its curves
    // plotted) while the Inspector stays with the forearm's explanation, with the way back.
    in_inspector(&harness, "upper_arm").click();
    settle(&mut harness);
    assert_eq!(harness.state().window.selection, vec![upper_arm]);
    harness.get_by_label("Fixes, best first");
    harness.get_by_label("upper_arm selected: its scale shows in the viewport");
    harness.get_by_label("back to forearm").click();
    settle(&mut harness);
    assert_eq!(harness.state().window.selection, vec![forearm]);
    // Another bone selected elsewhere lets the explanation go.
    in_inspector(&harness, "upper_arm").click();
    settle(&mut harness);
    in_pane(&harness, "Skeleton", "shoulder").click();
    settle(&mut harness);
    assert!(harness.query_by_label("back to forearm").is_none());
    harness.get_by_label("not sheared: nothing to explain");
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    // The first fix that is a setting of the document is a mode on the forearm; Try sets it on that bone alone.
    let declared = harness.state().session.doc.modes().to_vec();
    let fixes = ranked_fixes(harness.state(), forearm);
    let first = fixes.iter().find(|f| !matches!(f.change, Change::Bake { .. })).unwrap();
    let Change::Mode { bone: fixed, mode } = first.change else { panic!("{first:?}") };
    assert_eq!((fixed, first.removes), (forearm, true));
    in_inspector(&harness, "Try").click();
    settle(&mut harness);
    let app = harness.state();
    assert_eq!(app.session.doc.modes()[forearm], mode);
    assert!(app.session.doc.modes().iter().zip(&declared).enumerate().all(|(b, (m, d))| b == forearm || m == d));
    assert!(!app.analysis().unwrap().scan.bones[forearm].stretched(), "the analysis no longer flags the forearm");
    // The ghost shows the declared modes, as the clip was before.
    assert_eq!(app.session.doc.ghost, Some(Ghost::Modes(ModeChoice::Declared)));
    harness.get_by_label_contains(&format!("tried: forearm to {mode}"));
}

#[test]
fn after_a_try_the_fixes_stay_and_another_is_tried_in_its_place_one_undo_from_before() {
    let mut harness = why_forearm();
    let forearm = bone(&harness, "forearm");
    let before = state_of(&harness);
    in_inspector(&harness, "Try").click();
    settle(&mut harness);
    let first = harness.state().session.doc.modes()[forearm];
    // The ranking stays, the fix tried marked with Undo in its Try button's place; the shear plot draws the curve
    // before the fix dashed over the fixed one, without the ghost ticked by hand.
    harness.get_by_label("Fixes, best first");
    harness.get_by_label_contains(&format!("tried: forearm to {first}"));
    in_inspector(&harness, "Undo");
    in_pane(&harness, "Plots", "forearm shear° (ghost)");
    assert!(harness.state().settings.plot_ghost);
    // Noise is 0 in words as in the plots: no fix leaves "5.4e-6°".
    let effects = harness.query_all_by_role(Role::Label).filter_map(|n| n.value()).filter(|v| v.contains("° left)"));
    for effect in effects {
        assert!(!effect.contains("e-"), "{effect}");
    }
    // Another fix tried takes the first one's place: one step of the history, and one undo from the clip as opened.
    in_inspector(&harness, "Try").click();
    settle(&mut harness);
    let second = state_of(&harness);
    assert_ne!(second, before);
    assert_ne!(harness.state().session.doc.modes()[forearm], first, "the first fix taken back");
    harness.get_by_label_contains("tried: ");
    assert_eq!(harness.state().session.steps().0.len(), 2, "the clip as opened and the fix tried");
    undo_key(&mut harness);
    assert_eq!(state_of(&harness), before);
}

#[test]
fn what_was_tried_stays_in_its_place_at_the_worst_time_and_undo_takes_it_back() {
    let mut harness = why_forearm();
    let forearm = bone(&harness, "forearm");
    let before = state_of(&harness);
    let summary = harness.state().analysis().unwrap().scan.bones[forearm].clone();
    in_inspector(&harness, "Try").click();
    settle(&mut harness);
    // Try goes to the bone's worst time, where the change shows, and says what it did in the section's place.
    assert!((harness.state().window.time - summary.worst_shear_time).abs() < 1e-12);
    let mode = harness.state().session.doc.modes()[forearm];
    let said = format!("Tried: forearm to {mode}: shear {:.3}° before, 0° after; skin moved ", summary.worst_shear_deg);
    harness.get_by_label_contains(&said);
    in_inspector(&harness, "Undo").click();
    settle(&mut harness);
    assert_eq!(state_of(&harness), before, "Undo is the history's");
    assert!(harness.query_by_label_contains("Tried: ").is_none(), "undone, the line goes");
}

#[test]
fn why_tries_a_uniform_scale_that_the_layers_panel_removes() {
    use bonescope::app::Ghost;
    let mut harness = why_forearm();
    let (forearm, upper_arm) = (bone(&harness, "forearm"), bone(&harness, "upper_arm"));
    if harness.query_by_label("upper_arm's scale made uniform").is_none() {
        harness.get_by_label_contains(" more").click();
        settle(&mut harness);
    }
    let row = harness.get_by_label("upper_arm's scale made uniform");
    row.scroll_to_me();
    harness.run();
    let row = harness.get_by_label("upper_arm's scale made uniform").rect();
    let mut tries = harness.get_all_by_label("Try");
    tries.find(|t| (t.rect().center().y - row.center().y).abs() < 4.0).expect("its Try button").click();
    drop(tries);
    settle(&mut harness);
    let app = harness.state();
    assert_eq!(app.session.doc.layers().uniform_scale, vec![upper_arm]);
    assert!(!app.analysis().unwrap().scan.bones[forearm].stretched());
    assert_eq!(app.session.doc.ghost, Some(Ghost::Unlayered), "the ghost shows the clip without the layer");
    // The Layers panel lists the layer (its section opens for it) with a remove button that undoes it.
    harness.state_mut().settings.show(&bonescope::app::Pane::LAYERS, true);
    settle(&mut harness);
    harness.get_by_label("Uniform scale");
    let remove = harness.get_by_label("remove");
    remove.scroll_to_me();
    harness.run();
    harness.get_by_label("remove").click();
    settle(&mut harness);
    let app = harness.state();
    assert!(app.session.doc.layers().uniform_scale.is_empty());
    assert!(app.analysis().unwrap().scan.bones[forearm].stretched(), "flagged again");
}

/// Ctrl+Z, as a person presses it.
fn undo_key(harness: &mut Harness<'static, BonescopeApp>) {
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(harness);
}

/// Ctrl+Shift+Z.
fn redo_key(harness: &mut Harness<'static, BonescopeApp>) {
    harness.key_press_modifiers(egui::Modifiers::COMMAND | egui::Modifiers::SHIFT, egui::Key::Z);
    settle(harness);
}

/// What the document evaluates, and its ghost.
fn state_of(harness: &Harness<'static, BonescopeApp>) -> (bonescope::eval::Setup, Option<bonescope::app::Ghost>) {
    let doc = &harness.state().session.doc;
    (doc.setup().clone(), doc.ghost)
}

#[test]
fn a_fix_tried_is_undone_by_ctrl_z_with_its_ghost_and_redone_by_ctrl_shift_z() {
    let mut harness = why_forearm();
    let before = state_of(&harness);
    in_inspector(&harness, "Try").click();
    settle(&mut harness);
    let tried = state_of(&harness);
    assert_ne!(tried, before);
    // The Edit menu says what Undo undoes (the app's font has no arrow: "to").
    harness.get_by_label("Edit").click();
    harness.run();
    let forearm = bone(&harness, "forearm");
    let mode = harness.state().session.doc.modes()[forearm];
    harness.get_by_label_contains(&format!("Undo forearm to {mode}"));
    harness.key_press(egui::Key::Escape);
    harness.run();
    undo_key(&mut harness);
    assert_eq!(state_of(&harness), before, "modes, layers and ghost as they were");
    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label_contains(&format!("Redo forearm to {mode}"));
    harness.key_press(egui::Key::Escape);
    redo_key(&mut harness);
    assert_eq!(state_of(&harness), tried);
    // Ctrl+Y redoes too.
    undo_key(&mut harness);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Y);
    settle(&mut harness);
    assert_eq!(state_of(&harness), tried);
}

#[test]
fn a_subtree_mode_change_and_a_layer_added_are_one_step_each() {
    let mut harness = demo_app();
    let opened = state_of(&harness);
    harness.get_by_label("forearm").click_secondary();
    harness.run();
    harness.get_by_label("Set mode of its subtree").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "blender-aligned").click();
    settle(&mut harness);
    let subtree = state_of(&harness);
    let (forearm, hand) = (bone(&harness, "forearm"), bone(&harness, "hand"));
    assert!([forearm, hand].iter().all(|&b| harness.state().session.doc.modes()[b] == InheritMode::BlenderAligned));
    assert_eq!(harness.state().session.undo_label(), Some("forearm's subtree → blender-aligned"));
    blend_a_second_clip(&mut harness);
    assert_eq!(harness.state().session.undo_label(), Some("blend on"));
    undo_key(&mut harness);
    assert_eq!(state_of(&harness), subtree, "the blend alone is undone");
    undo_key(&mut harness);
    assert_eq!(state_of(&harness), opened, "then the subtree's modes, all at once");
    redo_key(&mut harness);
    redo_key(&mut harness);
    assert!(harness.state().session.doc.layers().blend.is_some());
}

#[test]
fn a_slider_dragged_over_many_frames_is_one_step() {
    let mut harness = layers_app(Document::demo());
    let before = state_of(&harness);
    let slider = harness.get_by_role_and_label(Role::Slider, "clip weight").rect();
    let (start, y) = (slider.left() + 0.98 * slider.width(), slider.center().y);
    harness.drag_at(egui::pos2(start, y));
    harness.run();
    for step in 1..=10 {
        harness.hover_at(egui::pos2(start - 0.05 * step as f32 * slider.width(), y));
        harness.run();
    }
    harness.drop_at(egui::pos2(start - 0.5 * slider.width(), y));
    settle(&mut harness);
    let weight = harness.state().session.doc.layers().bind_weight;
    assert!(weight < 0.9, "the slider moved: {weight}");
    assert_eq!(harness.state().session.undo_label(), Some(format!("bind weight {weight:.2}").as_str()));
    undo_key(&mut harness);
    assert_eq!(state_of(&harness), before, "one undo takes the whole drag back");
    assert_eq!(harness.state().session.undo_label(), None);
}

#[test]
fn a_reload_keeps_the_history_and_another_file_starts_a_new_one() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("walk.bvh");
    std::fs::copy(asset("bvh/bvh_test2.bvh"), &file).unwrap();
    let mut harness = demo_app();
    harness.state_mut().open(&file);
    settle(&mut harness);
    let opened = state_of(&harness);
    harness.get_by_role_and_label(Role::ComboBox, "Inherit scale").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "blender-none").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.undo_label(), Some("every bone → blender-none"));
    // The file changes on disk: it is read again, its history kept.
    std::fs::write(&file, std::fs::read_to_string(&file).unwrap().replace("Frame Time:", "Frame Time: ")).unwrap();
    let before = harness.state().session.doc.rig_id;
    for _ in 0..100 {
        std::thread::sleep(std::time::Duration::from_millis(20));
        harness.step();
        if harness.state().session.doc.rig_id != before {
            break;
        }
    }
    assert_ne!(harness.state().session.doc.rig_id, before, "reloaded");
    assert_eq!(harness.state().session.undo_label(), Some("every bone → blender-none"));
    undo_key(&mut harness);
    assert_eq!(state_of(&harness), opened);
    // Another file: nothing to undo or redo there.
    harness.state_mut().open(&asset("bvh/bvh_test3.bvh"));
    settle(&mut harness);
    assert_eq!((harness.state().session.undo_label(), harness.state().session.redo_label()), (None, None));
}

/// The worst shear, its time and the worst stretch the app's outliner shows (its analysis at the document's rate)
/// are `scan`'s, bone for bone, on every animation of every shared file: the shear refined between samples to
/// 0.001° whatever the rate, and both sampling where the other does.
#[test]
fn the_app_and_scan_report_one_worst_shear_stretch_and_time_on_every_shared_file() {
    use bonescope::analysis::{ScanOptions, scan};
    let folder = common::assets();
    let output = common::bonescope(&["scan", "--format", "jsonl", folder.to_str().unwrap()]);
    let mut compared = 0;
    for line in String::from_utf8(output.stdout).unwrap().lines() {
        let record: serde_json::Value = serde_json::from_str(line).unwrap();
        let Some(animations) = record["animations"].as_array().filter(|a| !a.is_empty()) else { continue };
        let path = std::path::PathBuf::from(record["file"].as_str().unwrap());
        let mut doc = Document::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for animation in animations {
            doc.set_clip(animation["animation"]["index"].as_u64().map(|i| i as usize)).unwrap();
            let options = ScanOptions { rate: doc.analysis_rate(), ..ScanOptions::default() };
            let app = scan(&doc.evaluation(), &options, &|_, _| {});
            let cli = animation["stretched"].as_array().unwrap();
            let shown: Vec<_> = app.stretched_worst_first();
            let place = format!("{} {}", path.display(), animation["animation"]);
            assert_eq!(shown.len(), cli.len(), "{place}: the same bones are flagged");
            for (bone, said) in shown.iter().zip(cli) {
                let figure = |key: &str| said[key].as_f64().unwrap();
                assert_eq!(said["index"].as_u64(), Some(bone.index as u64), "{place}");
                assert!((bone.worst_shear_deg - figure("worst_shear_deg")).abs() < 1e-3, "{place}: {said}");
                assert!((bone.worst_shear_time - figure("worst_shear_time")).abs() < 1e-4, "{place}: {said}");
                assert!((bone.worst_stretch_deg - figure("worst_stretch_deg")).abs() < 1e-3, "{place}: {said}");
                compared += 1;
            }
        }
    }
    assert!(compared >= 40, "the library has sheared bones to compare: {compared}");
}

// The new user's first minutes (issue 55): a tree that reads, controls that stay put, the small things.

/// The left edge of the row named `name` in the skeleton list.
fn row_left(harness: &Harness<'static, BonescopeApp>, name: &str) -> f32 {
    in_pane(harness, "Skeleton", name).rect().left()
}

#[test]
fn every_level_of_the_tree_steps_in_alike_and_names_hold_still_as_badges_come() {
    let mut harness = laptop_demo();
    let names = ["shoulder", "upper_arm", "forearm", "hand"];
    let lefts = |harness: &Harness<'static, BonescopeApp>| names.map(|name| row_left(harness, name));
    let at_start = lefts(&harness);
    let steps: Vec<f32> = at_start.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(steps.iter().all(|s| *s > 4.0 && (s - steps[0]).abs() < 0.5), "one step a level: {steps:?}");
    // At 0.5 s the forearm shears: its badge comes, and no name moves for it.
    harness.state_mut().window.time = 0.5;
    settle(&mut harness);
    let forearm = bone(&harness, "forearm");
    assert!(harness.state().analysis().unwrap().stretched_at(forearm, 15), "the forearm has a badge now");
    assert_eq!(lefts(&harness), at_start);
}

#[test]
fn a_click_on_a_rows_mode_selects_its_bone() {
    let mut harness = laptop_demo();
    let hand = in_pane(&harness, "Skeleton", "hand").rect();
    let mode = harness.get_all_by_label("full").find(|n| (n.rect().center().y - hand.center().y).abs() < 2.0);
    mode.expect("the hand's mode in its row").click();
    settle(&mut harness);
    assert_eq!(harness.state().window.selection, vec![bone(&harness, "hand")]);
}

#[test]
fn a_node_its_file_leaves_unnamed_reads_node_and_its_number() {
    use bonescope::model::{Bone, Skeleton};
    let mut rig = bonescope::import::demo_rig();
    let mut bones = rig.skeleton.bones().to_vec();
    let hand = bones.iter().position(|b| b.name == "hand").unwrap();
    bones[hand].name = Bone::unnamed(bones[hand].node);
    let node = bones[hand].node;
    rig.skeleton = Skeleton::new(bones).unwrap();
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), Document::new(None, rig))));
    settle(&mut harness);
    in_pane(&harness, "Skeleton", &format!("(node {node})"));
}

#[test]
fn a_barely_sheared_bone_says_how_little_not_zero() {
    let mut harness = laptop_demo();
    // Flag the least shear, and keep a thousandth of the clip: the forearm shears by a few hundredths of a degree.
    let tolerances = &mut harness.state_mut().settings.tolerances;
    (tolerances.min_anisotropy, tolerances.min_stretch_deg, tolerances.min_shear_deg) = (1e-9, 1e-9, 1e-9);
    let layers = bonescope::eval::Layers { bind_weight: 0.001, ..Default::default() };
    harness.state_mut().session.doc.set_layers(&layers).unwrap();
    settle(&mut harness);
    let forearm = bone(&harness, "forearm");
    let summary = &harness.state().analysis().unwrap().scan.bones[forearm];
    assert!(summary.stretched() && summary.worst_shear_deg < 0.05, "{}", summary.worst_shear_deg);
    let badges: Vec<String> =
        harness.query_all_by_role(Role::Label).filter_map(|n| n.value().filter(|v| v.starts_with("max "))).collect();
    assert!(badges.iter().all(|b| b != "max 0.0°") && !badges.is_empty(), "{badges:?}");
}

#[test]
fn a_drag_on_the_time_bar_lets_go_on_a_whole_frame() {
    let mut harness = demo_app();
    let bar = harness.get_by_label("time bar").rect();
    let y = bar.center().y;
    harness.drag_at(egui::pos2(bar.left() + 0.1 * bar.width(), y));
    harness.run();
    harness.hover_at(egui::pos2(bar.left() + 0.3 * bar.width(), y));
    harness.run();
    harness.drop_at(egui::pos2(bar.left() + 0.4337 * bar.width(), y));
    settle(&mut harness);
    let frame = harness.state().window.time * harness.state().session.doc.frame_rate();
    assert!(frame > 1.0 && (frame - frame.round()).abs() < 1e-9, "frame {frame}");
}

#[test]
fn undo_selects_the_bone_it_changes_back() {
    let mut harness = laptop_demo();
    in_pane(&harness, "Skeleton", "hand").click_secondary();
    harness.run();
    harness.get_by_label("Set mode of this bone").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "blender-aligned").click();
    settle(&mut harness);
    in_pane(&harness, "Skeleton", "shoulder").click();
    settle(&mut harness);
    undo_key(&mut harness);
    assert_eq!(harness.state().window.selection, vec![bone(&harness, "hand")]);
    // Edit → History lists the steps, the one undone among them.
    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label("History").click();
    harness.run();
    harness.get_by_label("opened");
    harness.get_by_label("hand to blender-aligned");
}

#[test]
fn an_error_goes_when_another_file_opens() {
    let mut harness = demo_app();
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.glb");
    std::fs::write(&broken, b"glTF\x02\x00\x00\x00").unwrap();
    harness.state_mut().open(&broken);
    harness.run();
    assert_eq!(harness.state().errors().len(), 1);
    harness.state_mut().open(&asset("bvh/bvh_test2.bvh"));
    settle(&mut harness);
    assert_eq!(harness.state().errors(), vec![], "the broken file's error is of the document before");
}

/// Opens bonescope's own browser from the File menu's `item`.
fn browse(harness: &mut Harness<'static, BonescopeApp>, item: &str) {
    harness.get_by_label("File").click();
    harness.run();
    harness.get_by_label(item).click();
    harness.run();
}

#[test]
fn open_and_compare_browse_in_one_window_in_the_folder_left() {
    let mut harness = demo_app();
    harness.state_mut().window.dialogs.native = bonescope::app::NativeDialog::Unavailable;
    browse(&mut harness, "Open…");
    harness.get_by_label("Up").click();
    harness.run();
    let folder = harness.get_by_label("Path").value();
    let place = harness.get_by_label("Open a file").rect().left_top();
    harness.get_by_label("Cancel").click();
    harness.run();
    browse(&mut harness, "Compare with…");
    assert_eq!(harness.get_by_label("Path").value(), folder);
    assert_eq!(harness.get_by_label("Compare with a file").rect().left_top(), place);
}

#[test]
fn a_file_opens_on_the_clip_that_keys_the_most_channels() {
    use bonescope::model::{BoneTracks, Clip};
    let mut rig = bonescope::import::demo_rig();
    let hand = rig.skeleton.find("hand").unwrap();
    let eyes = rig.clips[1].tracks_of(hand).unwrap().clone();
    let eyes = BoneTracks { translation: None, scale: None, ..eyes };
    let mut stretch = rig.clips[0].clone();
    stretch.index = 1;
    rig.clips = vec![Clip::new(0, Some("eyes only".into()), vec![eyes], vec![]), stretch];
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), Document::new(None, rig))));
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.clip().map(|c| c.label()).as_deref(), Some("stretch"));
}

#[test]
fn the_top_bar_holds_still_for_a_comparison_and_a_file_without_a_skin() {
    let mut harness = laptop_demo();
    let places = |harness: &Harness<'static, BonescopeApp>| {
        let combo = |label| harness.get_by_role_and_label(Role::ComboBox, label).rect();
        [combo("Ghost"), combo("Skinning"), harness.get_by_label("Layers").rect()]
    };
    let before = places(&harness);
    harness.state_mut().compare(&asset("bvh/cmu_12_01_walk.bvh"));
    settle(&mut harness);
    harness.get_by_label_contains("unit of");
    assert_eq!(places(&harness), before, "the comparison's pickers have a place of their own");
    harness.state_mut().open(&asset("bvh/bvh_test2.bvh"));
    settle(&mut harness);
    assert_eq!(places(&harness), before, "Skinning greyed, not gone");
}

#[test]
fn the_time_unit_picker_holds_still_for_another_clips_length() {
    let mut rig = bonescope::import::demo_rig();
    rig.clips[1] = rig.clips[1].clone().with_span(bonescope::model::Span::new(0.0, 12.5));
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(move |_cc| unopened(BonescopeApp::new(Settings::default(), Document::new(None, rig))));
    settle(&mut harness);
    let picker = |harness: &Harness<'static, BonescopeApp>| harness.get_by_role_and_label(Role::ComboBox, "in").rect();
    let before = picker(&harness);
    harness.state_mut().session.doc.set_clip(Some(1)).unwrap();
    settle(&mut harness);
    harness.get_by_label_contains("of 12.5");
    assert_eq!(picker(&harness), before);
}

#[test]
fn a_small_window_plots_taller_than_a_strip_under_a_top_bar_in_one_row() {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1000.0, 700.0))
        .build_eframe(|_cc| unopened(BonescopeApp::new(Settings::default(), Document::demo())));
    settle(&mut harness);
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let ctx = harness.ctx.clone();
    let memory = || egui_plot::PlotMemory::load(&ctx, bonescope::app::plot_id(0)).expect("the plot is shown");
    let height = memory().transform().frame().height();
    assert!(height > 45.0, "the plot is {height} points tall");
    // The top bar's controls in one row, the last as the first.
    let row = |rect: egui::Rect| rect.center().y;
    let first = row(harness.get_by_role_and_label(Role::ComboBox, "Animation").rect());
    assert_eq!(row(harness.get_by_label("Layers").rect()), first, "the top bar does not wrap");
}

#[test]
fn a_file_that_shears_opens_on_its_worst_bone_at_its_worst_time_with_why() {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(|_cc| BonescopeApp::new(Settings::default(), Document::demo()));
    settle(&mut harness);
    let worst = {
        let scan = &harness.state().analysis().expect("analysed").scan;
        let worst = scan.stretched_worst_first()[0];
        (worst.index, worst.worst_shear_time)
    };
    assert_eq!(worst.0, bone(&harness, "forearm"));
    assert_eq!(harness.state().window.selection, vec![worst.0]);
    assert_eq!(harness.state().window.time, worst.1);
    // Its shear is plotted, and the Why? section is open on its headline.
    harness.get_by_label("forearm shear°");
    settle(&mut harness);
    harness.get_by_label_contains("forearm: upper_arm's scale");
}

#[test]
fn a_file_without_shear_says_so_once_and_opens_at_its_start() {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .build_eframe(|_cc| BonescopeApp::new(Settings::default(), Document::demo()));
    harness.state_mut().open(&asset("bvh/cmu_12_01_walk.bvh"));
    settle(&mut harness);
    let app = harness.state();
    let (start, bones) = (app.session.doc.span().start, app.session.doc.rig.skeleton.len());
    assert!(app.window.selection.is_empty());
    assert_eq!(app.window.time, start);
    let clip = app.session.doc.clip().unwrap().label();
    let said = format!("no bone shears in `{clip}`: 0 of {bones} bones");
    assert_eq!(harness.get_all_by_label_contains(&said).count(), 1, "{said}");
}

#[test]
fn f_frames_the_selected_bone_and_everything_below_it() {
    use bonescope::view::{Camera, paint::projection};
    let mut harness = laptop_demo();
    in_pane(&harness, "Skeleton", "shoulder").click();
    settle(&mut harness);
    // Close up on the shoulder: the hand is far out of view.
    let shoulder = bone(&harness, "shoulder");
    let heads = |app: &BonescopeApp| -> Vec<glam::DVec3> {
        let pose = app.session.doc.evaluation().pose_at(app.window.time);
        pose.model.model.iter().map(|m| m.w_axis.truncate()).collect()
    };
    let target = heads(harness.state())[shoulder];
    harness.state_mut().settings.camera = Camera { target, distance: 0.05, ..Camera::default() };
    let canvas = harness.get_by_label("viewport").rect();
    harness.hover_at(canvas.center());
    harness.key_press(egui::Key::F);
    settle(&mut harness);
    let app = harness.state();
    // The picture is the canvas less the caption's strip of three lines (file and clip, time, mode).
    let picture = egui::Rect::from_min_max(canvas.min, egui::pos2(canvas.max.x, canvas.max.y - 3.0 * 17.0 - 8.0));
    let projection = projection(&app.settings.camera, picture);
    for (bone, head) in heads(app).into_iter().enumerate() {
        let (at, _) = projection.project(head).unwrap();
        let at = egui::pos2(at.x as f32, at.y as f32);
        assert!(picture.contains(at), "bone {bone} at {at:?}, outside {picture:?}");
    }
}

#[test]
fn the_axes_picker_chooses_whose_triads_are_drawn() {
    use bonescope::view::Triads;
    let mut harness = laptop_demo();
    assert_eq!(harness.state().settings.scene.triads, Triads::Stretched, "by default, where they help");
    harness.get_by_role_and_label(Role::ComboBox, "Axes").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "all").click();
    settle(&mut harness);
    assert_eq!(harness.state().settings.scene.triads, Triads::All);
}

#[test]
fn the_shear_toggle_sits_beside_mesh_and_greys_without_one() {
    let mut harness = laptop_demo();
    let (mesh, shear) = (harness.get_by_label("Mesh").rect(), harness.get_by_label("Shear").rect());
    assert!(shear.left() > mesh.right() && shear.left() - mesh.right() < 12.0, "{mesh:?} then {shear:?}");
    assert!((shear.center().y - mesh.center().y).abs() < 1.0, "on one row");
    assert!(harness.state().settings.scene.shear, "on by default");
    harness.get_by_label("Shear").click();
    settle(&mut harness);
    assert!(!harness.state().settings.scene.shear);
    harness.state_mut().open(&asset("bvh/cmu_12_01_walk.bvh"));
    settle(&mut harness);
    assert!(harness.get_by_label("Shear").accesskit_node().is_disabled(), "a mocap file has no mesh to paint");
    assert_eq!(harness.get_by_label("Shear").rect(), shear, "greyed, not gone");
}

#[test]
fn a_bvh_lying_along_z_opens_with_the_up_picker_and_stands_up_on_the_axis_picked() {
    // Blender writes its BVH Z-up: in the view's Y-up space the rig lies on the floor. The document's file gets the
    // picker and the line a compared file gets.
    let mut harness = asset_app("blender/stretchy_full.bvh");
    harness.get_by_label("lies along Z: the view stands along Y");
    let height = |harness: &Harness<'static, BonescopeApp>| {
        let pose = harness.state().session.doc.evaluation().pose_at(0.0);
        let (ys, zs): (Vec<f64>, Vec<f64>) = pose.model.model.iter().map(|m| (m.w_axis.y, m.w_axis.z)).unzip();
        let extent =
            |v: &[f64]| v.iter().copied().fold(f64::MIN, f64::max) - v.iter().copied().fold(f64::MAX, f64::min);
        (extent(&ys), extent(&zs))
    };
    let (y, z) = height(&harness);
    assert!(z > 1.5 * y, "lying: {y} high, {z} long");
    harness.get_by_role_and_label(Role::ComboBox, "up of stretchy_full.bvh").click();
    harness.run();
    harness.get_by_label("Z").click();
    settle(&mut harness);
    assert_eq!(harness.state().session.doc.stance.up, bonescope::model::UpAxis::Z);
    assert!(harness.query_by_label_contains("lies along").is_none(), "standing, nothing to say");
    let (y, z) = height(&harness);
    assert!(y > 1.5 * z, "standing: {y} high, {z} deep");
    // Standing is no edit of what is evaluated: nothing to undo, and the analysis is the stood rig's.
    assert_eq!(harness.state().session.undo_label(), None);
    assert!(harness.state().analysis().is_some());
}

/// A glTF of one node and one Draco-compressed mesh, `Tokyo`, whose stream is noise: it does not decode.
fn undecodable_draco(folder: &std::path::Path) -> std::path::PathBuf {
    use base64::Engine;
    let noise: Vec<u8> = (0u32..64).map(|i| (i * 37 + 11) as u8).collect();
    let data = base64::engine::general_purpose::STANDARD.encode(&noise);
    let gltf = serde_json::json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": ["KHR_draco_mesh_compression"],
        "extensionsRequired": ["KHR_draco_mesh_compression"],
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "name": "city", "mesh": 0 }],
        "meshes": [{ "name": "Tokyo", "primitives": [{
            "attributes": { "POSITION": 0 },
            "extensions": { "KHR_draco_mesh_compression": { "bufferView": 0, "attributes": { "POSITION": 0 } } }
        }] }],
        "accessors": [{ "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1] }],
        "bufferViews": [{ "buffer": 0, "byteLength": noise.len() }],
        "buffers": [{ "byteLength": noise.len(), "uri": format!("data:application/octet-stream;base64,{data}") }]
    });
    let path = folder.join("tokyo.gltf");
    std::fs::write(&path, gltf.to_string()).unwrap();
    path
}

#[test]
fn a_mesh_that_does_not_decode_is_named_on_opening_and_in_the_layers_panel() {
    let folder = tempfile::tempdir().unwrap();
    let path = undecodable_draco(folder.path());
    let mut harness = demo_app();
    harness.state_mut().open(&path);
    settle(&mut harness);
    // As `inspect` notes it: the mesh's name, where it is in the file, and why.
    let said = "not drawn, their compressed geometry does not decode: Tokyo at meshes[0].primitives[0]";
    harness.get_by_label_contains(said);
    harness.state_mut().settings.show(&bonescope::app::Pane::LAYERS, true);
    settle(&mut harness);
    in_pane(&harness, "Layers", "Meshes not drawn");
    let layers = harness.state().pane_rect(&bonescope::app::Pane::LAYERS).unwrap();
    let listed = harness.query_all_by_label_contains(said).filter(|n| layers.contains(n.rect().center())).count();
    assert_eq!(listed, 1, "the Layers panel names the mesh too");
}

#[test]
fn the_border_above_the_plots_is_grabbed_anywhere_in_its_gap_and_never_orbits_the_viewport() {
    // egui grabs a panel's edge within 3 points either side of it: the border between the viewport and the plots
    // is easier to grab, a press anywhere in its 8-point gap resizing and none orbiting the view or dragging a tab.
    for offset in [-3.5, -2.0, 0.0, 2.0, 3.5] {
        let mut harness = laptop_demo();
        let viewport = harness.state().pane_rect(&bonescope::app::Pane::VIEWPORT).unwrap();
        let plots = harness.state().pane_rect(&bonescope::app::Pane::named("Plots")).unwrap();
        let camera = harness.state().settings.camera;
        // The gap lies between the viewport's tile and the Plots tab's bar.
        let gap = 8.0;
        let start = egui::pos2(viewport.center().x, viewport.bottom() + 0.5 * gap + offset);
        let end = start + egui::vec2(0.0, 40.0);
        harness.hover_at(start);
        harness.run();
        harness.drag_at(start);
        harness.run();
        harness.hover_at(end);
        harness.run();
        harness.drop_at(end);
        harness.run();
        let after = harness.state().pane_rect(&bonescope::app::Pane::named("Plots")).unwrap();
        // The drag counts from where egui sees it start, a few points on.
        assert!(after.top() - plots.top() > 30.0, "{offset}: {} then {}", plots.top(), after.top());
        assert_eq!(harness.state().settings.camera, camera, "{offset}: the view did not orbit");
    }
}
