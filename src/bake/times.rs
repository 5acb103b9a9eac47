//! The times a clip is baked at first: every frame of the clip's rate, every key time, and a moment before every
//! stepped key (so a jump stays a jump instead of a ramp over a frame). [`super::refine`] adds what lies between
//! where the source needs it.

use crate::diff::Side;
use crate::model::{Clip, DEFAULT_FRAME_RATE, Interpolation, sample_times};

/// How long before a stepped key's jump the value before it is held (as the FBX importer and ufbx's baker do).
pub const STEP_LEAD: f64 = 1e-3;

/// The most frames baked at every one of; longer clips are thinned between sparse keys.
const MAX_FRAMES: usize = 1 << 20;

/// The sorted, distinct times to bake `side` at.
pub fn bake_times(side: &Side) -> Vec<f64> {
    let rate = side.clip.map_or(DEFAULT_FRAME_RATE, Clip::frame_rate);
    let mut keys = side.key_times();
    if side.layers.is_none() {
        keys.extend(side.clip.into_iter().flat_map(step_leads));
    }
    sample_times(keys, 0.0, side.duration(), rate, MAX_FRAMES).times
}

/// A moment before every key of a stepped track, but the first.
fn step_leads(clip: &Clip) -> Vec<f64> {
    let stepped = |times: &[f64], interpolation: Interpolation| {
        if interpolation == Interpolation::Step { times[1..].iter().map(|t| (t - STEP_LEAD).max(0.0)).collect() } else { Vec::new() }
    };
    let mut leads = Vec::new();
    for tracks in clip.tracks() {
        if let Some(t) = &tracks.translation {
            leads.extend(stepped(t.times(), t.interpolation()));
        }
        if let Some(r) = &tracks.rotation {
            leads.extend(stepped(r.times(), r.interpolation()));
        }
        if let Some(s) = &tracks.scale {
            leads.extend(stepped(s.times(), s.interpolation()));
        }
    }
    for morph in clip.morph() {
        for w in &morph.weights {
            leads.extend(stepped(w.times(), w.interpolation()));
        }
    }
    leads
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::Vec3;

    use super::*;
    use crate::import::demo_rig;
    use crate::model::{BoneTracks, Rig, Track};

    #[test]
    fn frames_keys_and_leads() {
        let mut rig = demo_rig();
        let times: Arc<[f64]> = vec![0.0, 0.25, 1.0].into();
        let mut tracks = BoneTracks::new(0);
        tracks.translation = Some(Track::new(times, vec![Vec3::ZERO, Vec3::X, Vec3::Y], Interpolation::Step).unwrap());
        rig.clips = vec![Clip::new(0, None, vec![tracks], vec![]).with_frame_rate(2.0)];
        let rig: Rig = rig;
        let side = Side::new(&rig, rig.clips.first(), &rig.skeleton.declared_modes());
        // Frames 0, 0.5, 1; keys 0.25; leads 0.249, 0.999.
        let expected = [0.0, 0.249, 0.25, 0.5, 0.999, 1.0];
        let got = bake_times(&side);
        assert_eq!(got.len(), expected.len(), "{got:?}");
        assert!(got.iter().zip(expected).all(|(g, e)| (g - e).abs() < 1e-12), "{got:?}");
    }
}
