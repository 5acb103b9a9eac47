//! Headless rendering (issue "Headless screenshots"): a cold `bonescope render` of the demo rig at 1280×720 (the
//! whole process: start, GPU set-up, frames, PNG) under 1 s, and a 100-frame sequence at 20 frames per second or
//! more. Both run the release binary as a pipeline would; the last bench isolates one frame's render and read-back.

use std::hint::black_box;
use std::process::Command;

use bonescope::app::{BonescopeApp, Chrome, Document, Settings};
use bonescope::render::{Background, Renderer};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

/// Runs `bonescope render` with `args` and the demo rig, writing into a scratch folder.
fn bonescope_render(args: &[&str], out: &std::path::Path) {
    let output = Command::new(env!("CARGO_BIN_EXE_bonescope"))
        .arg("render")
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("bonescope runs");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
}

fn cli(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("bonescope-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.bench_function("cold `bonescope render` demo 1280x720", |b| {
        b.iter(|| bonescope_render(&["--time", "0.5", "--size", "1280x720"], &dir.join("one.png")))
    });
    group.throughput(Throughput::Elements(100));
    group.bench_function("`bonescope render --frames 0:99:1` demo 1280x720", |b| {
        b.iter(|| bonescope_render(&["--frames", "0:99:1", "--size", "1280x720"], &dir.join("f{frame}.png")))
    });
    group.finish();
    let _ = std::fs::remove_dir_all(dir);
}

fn frame(c: &mut Criterion) {
    let mut app = BonescopeApp::new(Settings::default(), Document::demo());
    app.window.chrome = Chrome::ViewportOnly;
    let mut renderer = Renderer::new(app, 1280, 720, Background::Viewport).expect("a GPU or llvmpipe");
    let mut frame = 0u32;
    c.bench_function("render/frame only demo 1280x720 (render, read back)", |b| {
        b.iter(|| {
            frame = (frame + 1) % 60;
            black_box(renderer.render(f64::from(frame) / 30.0).expect("renders"))
        })
    });
}

criterion_group!(benches, cli, frame);
criterion_main!(benches);
