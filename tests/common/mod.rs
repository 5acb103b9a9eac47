//! Helpers shared by the integration tests that compare evaluated geometry with the authoring tools' own. (Each
//! test crate uses some of them.)
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use glam::DVec3;
use rayon::prelude::*;

/// A file of the shared assets beside the repository.
pub fn asset(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets").join(path)
}

/// The vertex positions (`v` lines) of a Wavefront OBJ file.
pub fn obj_positions(path: &Path) -> Vec<DVec3> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            DVec3::new(v[0], v[1], v[2])
        })
        .collect()
}

/// The diagonal of the bounding box.
pub fn size(points: &[DVec3]) -> f64 {
    let lo = points.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
    (hi - lo).length()
}

/// The largest distance from a point of either set to the nearest point of the other (the Hausdorff distance);
/// infinite when one set is empty and the other not.
pub fn hausdorff(a: &[DVec3], b: &[DVec3]) -> f64 {
    let one_way = |from: &[DVec3], to: &[DVec3]| {
        from.par_iter()
            .map(|p| to.iter().map(|q| p.distance_squared(*q)).fold(f64::INFINITY, f64::min))
            .reduce(|| 0.0, f64::max)
            .sqrt()
    };
    if a.is_empty() || b.is_empty() {
        return if a.len() == b.len() { 0.0 } else { f64::INFINITY };
    }
    one_way(a, b).max(one_way(b, a))
}
