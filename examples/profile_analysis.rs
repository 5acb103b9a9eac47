//! The whole-clip analysis of the app benchmark's rig, timed, for profilers (`perf record`): 500 bones in chains of
//! ten, a key every 5 frames, 8 plotted bones below scaled bones (see `benches/app_frame.rs`).
//!
//! `cargo build --profile bench --example profile_analysis`, then
//! `PLOT=8 THREADS=1 target/release/examples/profile_analysis 10000` (frames; `PLOT` plotted bones, `THREADS`
//! worker threads; `GHOST=segment-compensate` adds ghost curves under that mode). Prints the time of three runs and
//! the cost per bone-sample.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use bonescope::analysis::{CurveRequest, ScanOptions, analyze};
use bonescope::eval::Evaluation;
use bonescope::import::stress_rig;
use bonescope::model::InheritMode;

fn setting(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn main() {
    let frames = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(10_000);
    let rig = stress_rig(500, frames, 5);
    let plotted: Vec<usize> = (0..setting("PLOT", 8)).map(|i| 6 + 10 * i).collect();
    let ghost_mode = std::env::var("GHOST").ok().map(|id| id.parse::<InheritMode>().expect("a mode id"));
    let evaluation = Evaluation::declared(&rig, rig.clips.first());
    let ghost =
        ghost_mode.map(|mode| evaluation.with_modes(&vec![mode; rig.skeleton.len()]).expect("one mode per bone"));
    let options = ScanOptions { rate: 30.0, ..ScanOptions::default() };
    let never = AtomicBool::new(false);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(setting("THREADS", 1)).build().expect("a thread pool");
    for _ in 0..3 {
        let started = Instant::now();
        let analysis = pool.install(|| {
            let request = CurveRequest { bones: &plotted, ghost: ghost.as_ref(), ..Default::default() };
            analyze(&evaluation, request, &options, &|_, _| {}, &never).expect("never cancelled")
        });
        let seconds = started.elapsed().as_secs_f64();
        let bone_samples = analysis.times.len() * rig.skeleton.len();
        let stretched = analysis.scan.bones.iter().filter(|b| b.stretched()).count();
        println!(
            "{seconds:.3} s, {:.1} ns/bone-sample, {stretched} bones stretched",
            seconds * 1e9 / bone_samples as f64
        );
    }
}
