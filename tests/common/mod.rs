//! Helpers shared by the integration tests that compare evaluated geometry with the authoring tools' own.

use glam::DVec3;
use rayon::prelude::*;

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
