//! The app's frame on a big rig: 500 bones, a 100,000-frame clip, 8 plotted bones. Measures the CPU time of one
//! frame (layout, painting, plot reduction, tessellation) and the whole-clip analysis behind the plots.
//! Targets (issue "The desktop app"): a frame under 8 ms, the analysis under 2 s on 2 cores, memory under 1 GiB.
//!
//! And the curves of a newly selected bone on long mocap (issue "The app on real production files"): the CMU walk
//! (`../shared/assets/bvh`, 120 Hz) repeated 40 times, 175 s, judged down the selected bone's chain only (what the
//! app computes on a click, beside the rig-wide summary it keeps): target under 50 ms.

#[path = "support/shared_assets.rs"]
mod shared_assets;

use std::hint::black_box;
use std::time::Instant;

use bonescope::analysis::{CurveRequest, Judged, ScanOptions, analyze};
use bonescope::app::{BonescopeApp, Document, Settings};
use bonescope::eval::{Evaluation, Hierarchy};
use bonescope::import::stress_rig;
use criterion::{Criterion, criterion_group, criterion_main};

const BONES: usize = 500;
const FRAMES: usize = 100_000;
/// A rotation key every 5 frames on every bone: 20,001 keys per track.
const KEY_STEP: usize = 5;
const PLOTTED: usize = 8;

fn input(width: f32, height: f32) -> egui::RawInput {
    egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(width, height))),
        ..Default::default()
    }
}

fn app_frame(c: &mut Criterion) {
    // 1600×1000 with the default panels, and a small laptop window with Layers and Inspector open.
    let windows = [("", 1600.0, 1000.0, false), (", 1000×700 with Layers", 1000.0, 700.0, true)];
    for (name, width, height, show_layers) in windows {
        let settings = Settings::default().showing(&bonescope::app::Pane::LAYERS, show_layers);
        frame_in(c, &format!("app frame, 500 bones, 100k frames, 8 curves{name}"), settings, input(width, height));
    }
}

fn frame_in(c: &mut Criterion, name: &str, settings: Settings, input: egui::RawInput) {
    let rig = stress_rig(BONES, FRAMES, KEY_STEP);
    let mut app = BonescopeApp::new(settings, Document::new(None, rig));
    // The eight plotted bones sit below scaled bones, so they shear.
    app.window.selection = (0..PLOTTED).map(|i| 6 + 10 * i).collect();
    app.window.time = 1234.5;
    let ctx = egui::Context::default();
    let started = Instant::now();
    app.settle();
    eprintln!("whole-clip analysis in the app (settle): {:.2} s", started.elapsed().as_secs_f64());
    // Two warm-up frames: fonts, layout caches, the plot's first reduction.
    for _ in 0..2 {
        let _ = ctx.run_ui(input.clone(), |ui| app.ui(ui));
    }
    c.bench_function(name, |b| {
        b.iter(|| {
            let output = ctx.run_ui(input.clone(), |ui| app.ui(ui));
            black_box(ctx.tessellate(output.shapes, output.pixels_per_point))
        })
    });
}

fn clip_analysis(c: &mut Criterion) {
    let rig = stress_rig(BONES, FRAMES, KEY_STEP);
    let modes = rig.skeleton.declared_modes();
    let hierarchy = Hierarchy::new(&rig.skeleton, &modes).unwrap();
    let plotted: Vec<usize> = (0..PLOTTED).map(|i| 6 + 10 * i).collect();
    let options = ScanOptions { rate: bonescope::model::DEFAULT_FRAME_RATE, ..ScanOptions::default() };
    let mut group = c.benchmark_group("whole-clip analysis");
    group.sample_size(10);
    group.bench_function("500 bones, 100k frames, 8 curves (rayon, all cores)", |b| {
        b.iter(|| {
            let request = CurveRequest { bones: &plotted, ghost: None, ..Default::default() };
            black_box(analyze_clip(&rig, &hierarchy, request, &options))
        })
    });
    group.finish();
}

fn selection_curves(c: &mut Criterion) {
    let rig = shared_assets::repeated_cmu_walk(40);
    let clip = rig.clips.first();
    eprintln!("repeated CMU walk: {:.1} s, {} bones", clip.map_or(0.0, |c| c.span().length()), rig.skeleton.len());
    let hierarchy = Hierarchy::new(&rig.skeleton, &rig.skeleton.declared_modes()).unwrap();
    let hand = rig.skeleton.bones().iter().position(|b| b.name.contains("Hand")).unwrap_or(rig.skeleton.len() - 1);
    let options = ScanOptions { rate: clip.map_or(30.0, |c| c.frame_rate()), ..ScanOptions::default() };
    let mut group = c.benchmark_group("selection curves");
    group.sample_size(10);
    for (name, judged) in [("chain only (the app on a click)", Judged::CurveChains), ("every bone", Judged::Every)] {
        group.bench_function(format!("CMU walk ×40 (175 s, 120 Hz), one bone, {name}"), |b| {
            b.iter(|| {
                let request = CurveRequest { bones: &[hand], ghost: None, judged };
                black_box(analyze_clip(&rig, &hierarchy, request, &options))
            })
        });
    }
    group.finish();
}

/// The whole-clip analysis of the rig's first clip, never cancelled.
fn analyze_clip(
    rig: &bonescope::model::Rig,
    hierarchy: &Hierarchy,
    request: CurveRequest,
    options: &ScanOptions,
) -> Option<bonescope::analysis::ClipAnalysis> {
    let never = std::sync::atomic::AtomicBool::new(false);
    let evaluation = Evaluation::new(rig, rig.clips.first(), hierarchy.modes()).unwrap();
    analyze(&evaluation, request, options, &|_, _| {}, &never)
}

criterion_group!(benches, app_frame, clip_analysis, selection_curves);
criterion_main!(benches);
