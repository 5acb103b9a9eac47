//! The desktop app driven as a person would, through egui_kittest: select by label, change modes, step frames,
//! and check what the panels show.

use bonescope::app::{BonescopeApp, Document, Settings};
use bonescope::model::InheritMode;
use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

fn demo_app() -> Harness<'static, BonescopeApp> {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .build_eframe(|_cc| BonescopeApp::new(Settings::default(), Document::demo()));
    settle(&mut harness);
    harness
}

/// Processes pending input, lets the background analysis it started finish, then lets the UI catch up. (A bare
/// `run()` while the analysis runs would keep stepping until kittest gives up.)
fn settle(harness: &mut Harness<'static, BonescopeApp>) {
    harness.step();
    let ctx = harness.ctx.clone();
    harness.state_mut().settle(&ctx);
    harness.run();
}

fn bone(harness: &Harness<'static, BonescopeApp>, name: &str) -> usize {
    harness.state().doc.rig.skeleton.find(name).unwrap()
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
    harness.state_mut().time = 0.5;
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let forearm = bone(&harness, "forearm");
    assert_eq!(harness.state().selection, vec![forearm]);
    harness.get_by_label_contains("inherit full");
    // At 0.5 s the upper arm is stretched to 1.6× and the forearm bent: under full inheritance it shears.
    harness.get_by_label("findings: stretched (shear)");
    harness.get_by_label("Copy as JSON");
}

#[test]
fn changing_every_bone_to_segment_compensate_removes_the_shear() {
    let mut harness = demo_app();
    harness.state_mut().time = 0.5;
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    harness.get_by_role_and_label(Role::ComboBox, "Inherit scale").click();
    harness.run();
    harness.get_by_role_and_label(Role::Button, "segment-compensate").click();
    settle(&mut harness);
    let app = harness.state();
    assert!(app.doc.modes.iter().all(|&m| m == InheritMode::SegmentCompensate));
    harness.get_by_label("findings: none");
    // The whole-clip analysis agrees: nothing is stretched any more.
    assert!(app.analysis().unwrap().scan.bones.iter().all(|b| !b.stretched()));
}

#[test]
fn arrow_keys_step_one_frame_and_space_plays() {
    let mut harness = demo_app();
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    harness.key_press(egui::Key::ArrowRight);
    harness.run();
    assert!((harness.state().time - 2.0 / 30.0).abs() < 1e-12);
    harness.key_press(egui::Key::ArrowLeft);
    harness.run();
    assert!((harness.state().time - 1.0 / 30.0).abs() < 1e-12);
    harness.key_press(egui::Key::Space);
    harness.step();
    assert!(harness.state().playing);
    harness.get_by_label("Pause").click();
    harness.run();
    assert!(!harness.state().playing);
}

#[test]
fn a_file_that_fails_to_load_keeps_the_document_and_says_why() {
    let mut harness = demo_app();
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.glb");
    std::fs::write(&broken, b"glTF\x02\x00\x00\x00").unwrap();
    harness.state_mut().open(&broken);
    harness.run();
    assert!(harness.state().doc.path.is_none(), "still the demo");
    harness.get_by_label_contains("broken.glb");
}

#[test]
fn the_timeline_strip_and_plots_follow_the_analysis() {
    let mut harness = demo_app();
    harness.get_by_label("forearm").click();
    settle(&mut harness);
    let app = harness.state();
    let analysis = app.analysis().expect("analysis for the current state");
    let forearm = bone(&harness, "forearm");
    let curves = analysis.curves_of(forearm).expect("curves of the plotted bone");
    assert_eq!(curves.model.len(), analysis.times.len());
    assert_eq!(curves.ghost_model.len(), analysis.times.len(), "the demo opens with a ghost");
    // Stretched while the upper arm is scaled, not at t = 0.
    assert!(!analysis.stretched_at(forearm, 0));
    assert!((0..analysis.times.len()).any(|s| analysis.stretched_at(forearm, s)));
}
