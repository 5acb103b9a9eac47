//! The shared assets beside the repository (`../shared/assets`), for the benchmarks and examples that load them.

use std::path::{Path, PathBuf};

/// The shared assets' folder.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets")
}

/// A file of the shared assets (`FOLDER/NAME`).
pub fn asset(path: &str) -> PathBuf {
    root().join(path)
}

/// The CMU walk of `bvh/` (120 Hz) with its motion repeated `times` times: long mocap, built rather than stored.
pub fn repeated_cmu_walk(times: usize) -> bonescope::model::Rig {
    let path = asset("bvh/cmu_12_01_walk.bvh");
    let text = std::fs::read_to_string(&path).expect("../shared/assets/bvh/cmu_12_01_walk.bvh");
    let (header, motion) = text.split_once("MOTION").unwrap();
    let mut lines = motion.lines().filter(|l| !l.trim().is_empty());
    let frames: usize = lines.next().unwrap().trim().trim_start_matches("Frames:").trim().parse().unwrap();
    let frame_time = lines.next().unwrap();
    let values: Vec<&str> = lines.collect();
    let repeated = vec![values.join("\n"); times].join("\n");
    let bytes = format!("{header}MOTION\nFrames: {}\n{frame_time}\n{repeated}\n", frames * times);
    bonescope::import::load_bytes(&path, bytes.as_bytes()).unwrap()
}
