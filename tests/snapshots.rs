//! Pictures of the main views with the demo rig, compared with the committed ones in `tests/snapshots/`
//! (`UPDATE_SNAPSHOTS=1 cargo test --test snapshots` rewrites them; look at them before committing).

mod common;

use bonescope::app::{BonescopeApp, Document, Settings};
use bonescope::view::ViewKind;
use common::{asset, finish_analysis};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

/// The app on `doc` at `time` in a 1400×900 window, with `bone` selected (when given) and the analysis settled.
fn window(settings: Settings, doc: Document, time: f64, bone: Option<&str>) -> Harness<'static, BonescopeApp> {
    let mut harness = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .with_render_cursor(false)
        .wgpu()
        .build_eframe(move |_cc| chosen(BonescopeApp::new(settings, doc)));
    harness.state_mut().window.time = time;
    if let Some(bone) = bone {
        harness.get_by_label(bone).click();
    }
    settle_for_snapshot(&mut harness);
    harness
}

/// `app` for a picture whose bone and time the test chooses: without the first view its analysis would set
/// ([`bonescope::app::Window::opening`]), which the `first_view` pictures show.
fn chosen(mut app: BonescopeApp) -> BonescopeApp {
    app.window.opening = false;
    app
}

/// Lets the background analysis finish, then runs a fixed number of frames rather than `common::settle`'s `run()`:
/// the analysis thread's wake-up may land in any step, and the plot needs a few frames to fit its bounds to the
/// curves.
fn settle_for_snapshot(harness: &mut Harness<'static, BonescopeApp>) {
    finish_analysis(harness);
    harness.run_steps(8);
}

/// The demo at 0.5 s (upper arm stretched, forearm bent) with boxes on and the forearm selected.
fn app(configure: impl FnOnce(&mut Settings)) -> Harness<'static, BonescopeApp> {
    let mut settings = Settings::default();
    settings.scene.boxes = true;
    configure(&mut settings);
    window(settings, Document::demo(), 0.5, Some("forearm"))
}

#[test]
fn demo_perspective_with_ghost() {
    app(|_| {}).snapshot("demo_perspective_with_ghost");
}

/// The Inspector's Why? section open on the demo's forearm: the upper arm's squash as the main cause, its time
/// spans, and the fixes ranked with their costs. The README shows this snapshot as the picture of the section.
#[test]
fn demo_why_forearm() {
    why_forearm().snapshot("demo_why_forearm");
}

/// The demo with the forearm's Why? section open and explained.
fn why_forearm() -> Harness<'static, BonescopeApp> {
    let mut harness = app(|_| {});
    harness.get_by_label("Why?").click();
    // The explanation starts once the section is open: wait for it before the fixed frames.
    for _ in 0..20 {
        finish_analysis(&mut harness);
        if harness.query_by_label("Fixes, best first").is_some() {
            break;
        }
    }
    settle_for_snapshot(&mut harness);
    harness
}

/// The first fix tried (the forearm's mode), then the Edit menu open: Undo says what it takes back, with its key;
/// the ghost shows the clip as it was.
#[test]
fn demo_edit_menu_after_a_fix_tried() {
    let mut harness = why_forearm();
    let inspector = harness.state().pane_rect(&bonescope::app::Pane::named("Inspector")).unwrap();
    let mut tries = harness.get_all_by_label("Try");
    tries.find(|t| inspector.contains(t.rect().center())).expect("a Try button").click();
    drop(tries);
    settle_for_snapshot(&mut harness);
    harness.get_by_label("Edit").click();
    harness.run_steps(4);
    harness.snapshot("demo_edit_menu_after_a_fix_tried");
}

#[test]
fn demo_front_view_with_ghost() {
    app(|s| s.camera.view = ViewKind::Front).snapshot("demo_front_view_with_ghost");
}

#[test]
fn demo_light_theme_euler_plots() {
    app(|s| {
        s.dark = false;
        s.rotation_format = bonescope::app::RotationFormat::Euler;
    })
    .snapshot("demo_light_theme");
}

#[test]
fn demo_stretch_plots_with_ghost_and_only_flagged_bones() {
    let mut harness = app(|_| {});
    // One click a frame: egui takes one press and release per pointer per frame.
    harness.get_by_role_and_label(egui::accesskit::Role::Button, "stretch U").click();
    harness.step();
    harness.get_by_label("ghost").click();
    harness.step();
    harness.get_by_label("Only flagged").click();
    settle_for_snapshot(&mut harness);
    harness.snapshot("demo_stretch_plots_with_ghost");
}

/// A clip far longer than the plot is wide: curves drawn as min/max envelopes, stretched bands merged per pixel.
#[test]
fn long_clip_envelopes() {
    let rig = bonescope::import::stress_rig(20, 20_000, 5);
    let mut harness = window(Settings::default(), Document::new(None, rig), 300.0, None);
    harness.state_mut().window.selection = vec![6, 16];
    settle_for_snapshot(&mut harness);
    harness.snapshot("long_clip_envelopes");
}

/// The Layers panel with a synced blend into the demo's bend, an additive bend and a shake on the forearm, and the
/// viewport showing their sum over the unlayered clip (the ghost).
#[test]
fn demo_layers_blend_additive_shake() {
    use bonescope::app::Ghost;
    use bonescope::eval::Layers;
    use bonescope::eval::layers::{Additive, Blend, Shake, ShakeParams};
    let mut doc = Document::demo();
    let forearm = doc.rig.skeleton.find("forearm").unwrap();
    let layers = Layers {
        blend: Some(Blend { clip: 1, weight: 0.5, sync: true, rotation: Default::default() }),
        additive: Some(Additive { clip: 1, reference: Default::default(), order: Default::default(), weight: 0.5 }),
        shake: Some(Shake { bone: forearm, params: ShakeParams::default() }),
        ..Layers::default()
    };
    doc.set_layers(&layers).unwrap();
    doc.ghost = Some(Ghost::Unlayered);
    let mut settings = Settings::default()
        .showing(&bonescope::app::Pane::LAYERS, true)
        .showing(&bonescope::app::Pane::named("Inspector"), false);
    settings.scene.boxes = true;
    window(settings, doc, 0.4, Some("forearm")).snapshot("demo_layers_blend_additive_shake");
}

/// A file of ufbx's corpus (`../shared/assets/fbx-ufbx-corpus`) as a document.
fn corpus_document(name: &str) -> Document {
    asset_document(&format!("fbx-ufbx-corpus/{name}"))
}

/// Maya's dual-quaternion skin mid-twist: the mesh keeps its volume where linear blending would pinch it.
#[test]
fn fbx_dual_quaternion_skin_twisted() {
    let doc = corpus_document("maya_dual_quaternion_7500_ascii.fbx");
    window(Settings::default(), doc, 2.5, Some("joint2")).snapshot("fbx_dual_quaternion_skin_twisted");
}

/// Maya's in-between blend shapes at 2.5 s: the cube's top lifted and moved aside, the Inspector listing every
/// shape's weight in effect.
#[test]
fn fbx_blend_shapes_with_inbetweens() {
    let doc = corpus_document("maya_blend_inbetween_7500_ascii.fbx");
    window(Settings::default(), doc, 2.5, Some("pCube1")).snapshot("fbx_blend_shapes_with_inbetweens");
}

/// Blender's FBX stores its current frame, the forearm turned 20° from where the mesh was bound: the Layers panel's
/// bind check notes the stored pose, with no warning.
#[test]
fn fbx_stored_pose_noted_in_the_layers_panel() {
    let settings = Settings::default().showing(&bonescope::app::Pane::LAYERS, true);
    let doc = asset_document("blender/stretchy_full.fbx");
    window(settings, doc, 0.0, None).snapshot("fbx_stored_pose_noted_in_the_layers_panel");
}

/// A shared asset (`../shared/assets/FOLDER/NAME`) as a document.
fn asset_document(path: &str) -> Document {
    let path = asset(path);
    let rig = bonescope::import::load(&path).unwrap_or_else(|e| panic!("{e}"));
    Document::new(Some(path), rig)
}

/// Maya's centimetre rig (converted by a 0.01 scale at its top) at 0.5 s, seen from the side where its shear lies:
/// triads and boxes at the rig's size, the boxes of the segment-compensated bones slanted.
#[test]
fn maya_centimetre_rig_sheared_gizmos() {
    let mut settings = Settings::default();
    settings.scene.boxes = true;
    settings.camera.view = ViewKind::Side;
    let doc = asset_document("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx");
    window(settings, doc, 0.5, None).snapshot("maya_centimetre_rig_sheared_gizmos");
}

/// CMU mocap in centimetres, not converted: gizmos at the rig's size too.
#[test]
fn cmu_walk_gizmos() {
    let mut settings = Settings::default();
    settings.scene.boxes = true;
    window(settings, asset_document("bvh/cmu_12_01_walk.bvh"), 1.0, None).snapshot("cmu_walk_gizmos");
}

/// 3ds Max's walk: the biped in the tree, its six "Producer" cameras, three cameras with their targets, a sky light
/// and the footsteps in their own group, opened (it starts collapsed).
#[test]
fn walk_outliner_with_cameras_and_helpers() {
    let mut harness = window(Settings::default(), asset_document("fbx-proanimationbank/walk.fbx"), 0.0, None);
    harness.get_by_label_contains("Cameras, lights and helpers").click();
    settle_for_snapshot(&mut harness);
    harness.snapshot("walk_outliner_with_cameras_and_helpers");
}

/// A small laptop window, 1000×700, with the Layers panel and the Inspector open: the Inspector and the Layers
/// share a column, the toolbar wraps rather than cut its controls.
#[test]
fn small_window_with_layers_and_inspector() {
    let settings = Settings::default().showing(&bonescope::app::Pane::LAYERS, true);
    laptop(egui::vec2(1000.0, 700.0), settings, Document::demo(), "forearm", 0.5)
        .snapshot("small_window_with_layers_and_inspector");
}

/// A laptop's window, 1280×800, with the Layers and the Inspector open on a studio's file, one of its bones
/// inspected: every matrix column, name and number whole.
fn laptop(
    size: egui::Vec2,
    settings: Settings,
    doc: Document,
    bone: &str,
    time: f64,
) -> Harness<'static, BonescopeApp> {
    let index = doc.rig.skeleton.find(bone).unwrap_or_else(|| panic!("{bone}"));
    let mut harness = Harness::builder()
        .with_size(size)
        .with_render_cursor(false)
        .wgpu()
        .build_eframe(move |_cc| chosen(BonescopeApp::new(settings, doc)));
    harness.state_mut().window.time = time;
    harness.state_mut().window.selection = vec![index];
    settle_for_snapshot(&mut harness);
    harness
}

fn laptop_settings() -> Settings {
    Settings::default().showing(&bonescope::app::Pane::LAYERS, true)
}

#[test]
fn laptop_maya_mixed_inherit_modes() {
    let doc = asset_document("fbx-ufbx-data/maya_mixed_inherit_mode_7700_ascii.fbx");
    laptop(egui::vec2(1280.0, 800.0), laptop_settings(), doc, "Left_Tip", 0.5)
        .snapshot("laptop_maya_mixed_inherit_modes");
}

#[test]
fn laptop_maya_human_ik() {
    let doc = asset_document("fbx-ufbx-corpus/maya_human_ik_6100_binary.fbx");
    laptop(egui::vec2(1280.0, 800.0), laptop_settings(), doc, "Character1_RightHandMiddle3", 0.0)
        .snapshot("laptop_maya_human_ik");
}

/// HumanIK's character in centimetres with every bone under full inheritance, its declared segment-compensate as
/// the ghost: the unit's 0.01 stands outside the rig, so neither mode compensates it and the ghost and the pose
/// are one size (they once stood 100× apart).
#[test]
fn laptop_maya_character_full_with_a_compensating_ghost() {
    use bonescope::app::{Ghost, ModeScope};
    use bonescope::model::{InheritMode, ModeChoice};
    let mut doc = asset_document("fbx-ufbx-corpus/maya_character_7500_binary.fbx");
    doc.set_mode(0, ModeScope::All, ModeChoice::Mode(InheritMode::Full));
    doc.ghost = Some(Ghost::Modes(ModeChoice::Mode(InheritMode::SegmentCompensate)));
    laptop(egui::vec2(1280.0, 800.0), laptop_settings(), doc, "Character1_LeftForeArm", 0.0)
        .snapshot("laptop_maya_character_full_with_a_compensating_ghost");
}

/// Axis-angle curves: the angle in degrees and the unit axis in two plots sharing the time axis, the legend above
/// them.
#[test]
fn demo_axis_angle_in_two_plots() {
    app(|s| s.rotation_format = bonescope::app::RotationFormat::AxisAngle).snapshot("demo_axis_angle_in_two_plots");
}

/// The demo under segment scale compensate, compared with its own bake as the closest TRS per bone (what a runtime
/// that cannot shear plays): the ghost parts from the pose at the forearm, whose stretch the TRS lost, and the
/// outliner badges the bones that stray; the plots show the bake's curves dashed.
#[test]
fn demo_compared_with_its_trs_bake() {
    use bonescope::model::InheritMode;
    let folder = tempfile::tempdir().unwrap();
    let rig = bonescope::import::demo_rig();
    let modes = vec![InheritMode::SegmentCompensate; rig.skeleton.len()];
    let source = bonescope::eval::Evaluation::new(&rig, None, &modes).unwrap();
    let (trs, tolerance) = (bonescope::bake::Strategy::Trs, bonescope::bake::DEFAULT_TOLERANCE);
    let request = bonescope::bake::Request::every_clip(&source, None, trs, tolerance);
    let baked = folder.path().join("demo_trs.glb");
    bonescope::bake::save(&baked, &bonescope::bake::bake(&request).bytes).unwrap();
    let mut doc = Document::demo();
    let compensate = bonescope::model::ModeChoice::Mode(InheritMode::SegmentCompensate);
    doc.set_mode(0, bonescope::app::ModeScope::All, compensate);
    doc.compare_with(bonescope::app::Compared::load(&baked, &doc.rig).unwrap());
    let mut settings = Settings::default();
    settings.scene.boxes = true;
    settings.camera.view = ViewKind::Front;
    let mut harness = window(settings, doc, 0.5, Some("forearm"));
    harness.get_by_label("ghost").click();
    settle_for_snapshot(&mut harness);
    harness.snapshot("demo_compared_with_its_trs_bake");
}

/// The first view of a file as it opens, nothing chosen: the worst bone selected at its worst time, its skin
/// painted by shear, its shear plotted and the Why? section open; the figure filling the viewport.
fn first_view(size: egui::Vec2, doc: Document) -> Harness<'static, BonescopeApp> {
    let mut harness = Harness::builder()
        .with_size(size)
        .with_render_cursor(false)
        .wgpu()
        .build_eframe(move |_cc| BonescopeApp::new(Settings::default(), doc));
    settle_for_snapshot(&mut harness);
    // The Why? section explains off the UI thread once the bone is selected.
    settle_for_snapshot(&mut harness);
    harness
}

const LAPTOP: egui::Vec2 = egui::vec2(1280.0, 800.0);
const SMALL: egui::Vec2 = egui::vec2(1000.0, 700.0);

/// The first view of `doc` in a laptop's window and a small one, as `first_view_NAME.png` and
/// `first_view_NAME_1000x700.png`.
fn first_views(name: &str, doc: impl Fn() -> Document) {
    let mut results = egui_kittest::SnapshotResults::new();
    for (size, suffix) in [(LAPTOP, ""), (SMALL, "_1000x700")] {
        let mut harness = first_view(size, doc());
        harness.snapshot(format!("first_view_{name}{suffix}"));
        results.extend_harness(&mut harness);
    }
    results.unwrap();
}

/// A file of the shared corpus (`../shared/corpus/FOLDER/NAME`) as a document.
fn corpus_file(path: &str) -> Document {
    let path = common::corpus(path);
    let rig = bonescope::import::load(&path).unwrap_or_else(|e| panic!("{e}"));
    Document::new(Some(path), rig)
}

#[test]
fn first_view_demo() {
    first_views("demo", Document::demo);
}

#[test]
fn first_view_blender_stretchy_full() {
    first_views("stretchy_full", || asset_document("blender/stretchy_full.glb"));
}

#[test]
fn first_view_godot_mannequiny() {
    first_views("godot_mannequiny", || corpus_file("realworld/godot_mannequiny.glb"));
}

#[test]
fn first_view_maya_human_ik() {
    first_views("maya_human_ik", || corpus_document("maya_human_ik_7400_binary.fbx"));
}

#[test]
fn first_view_robot_expressive_usd() {
    first_views("robot_expressive_usdc", || corpus_file("blender-io/RobotExpressive.usdc"));
}

#[test]
fn first_view_cmu_walk() {
    first_views("cmu_walk", || asset_document("bvh/cmu_12_01_walk.bvh"));
}
