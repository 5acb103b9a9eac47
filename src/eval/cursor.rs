//! A clip read one bone and one channel at a time, for callers that need only some of them: a whole-clip analysis
//! reads a bone's rotation only where its parent stretches unevenly, and never its translation unless it plots the
//! bone.

use glam::{DQuat, DVec3, Quat};

use super::sample::{Span, key_value, sample_track_near};
use crate::math::Slerp;
use crate::model::{BoneTracks, Clip, Interpolation, Skeleton, Track, Transform};

const TRANSLATION: u8 = 1;
const ROTATION: u8 = 2;
const SCALE: u8 = 4;

/// Samples channels of `clip` at the time last given to [`ClipCursor::seek`], each at most once per time, with
/// the values of [`super::sample_clip`]. Increasing times (a scan's order) skip the key searches, as
/// [`super::Pose`] does.
#[derive(Clone, Debug)]
pub struct ClipCursor<'a> {
    skeleton: &'a Skeleton,
    /// Each bone's tracks, when the clip animates it.
    tracks: Vec<Option<&'a BoneTracks>>,
    /// Where each bone's translation, rotation and scale keys were found last.
    hints: Vec<[usize; 3]>,
    time: f64,
    /// The channels sampled at `time` so far (bits `TRANSLATION | ROTATION | SCALE`), and their values.
    sampled: Vec<u8>,
    values: Vec<Transform>,
    /// Each bone's last rotation key interval and its slerp.
    slerps: Vec<(usize, Slerp)>,
}

impl<'a> ClipCursor<'a> {
    pub fn new(skeleton: &'a Skeleton, clip: &'a Clip) -> Self {
        let mut tracks = vec![None; skeleton.len()];
        for bone_tracks in clip.tracks() {
            if let Some(slot) = tracks.get_mut(bone_tracks.bone) {
                *slot = Some(bone_tracks);
            }
        }
        ClipCursor {
            skeleton,
            hints: vec![[0; 3]; tracks.len()],
            sampled: vec![0; tracks.len()],
            values: skeleton.bones().iter().map(|b| b.rest).collect(),
            slerps: vec![(usize::MAX, Slerp::new(DQuat::IDENTITY, DQuat::IDENTITY)); tracks.len()],
            tracks,
            time: 0.0,
        }
    }

    /// Moves to `time` (seconds).
    pub fn seek(&mut self, time: f64) {
        self.time = time;
        self.sampled.fill(0);
    }

    pub fn translation(&mut self, bone: usize) -> DVec3 {
        if self.fresh(bone, TRANSLATION) {
            let track = self.tracks[bone].and_then(|t| t.translation.as_ref());
            self.values[bone].translation = match track {
                Some(track) => sample_track_near(track, self.time, &mut self.hints[bone][0]),
                None => self.skeleton.bone(bone).rest.translation,
            };
        }
        self.values[bone].translation
    }

    pub fn rotation(&mut self, bone: usize) -> DQuat {
        if self.fresh(bone, ROTATION) {
            let track = self.tracks[bone].and_then(|t| t.rotation.as_ref());
            self.values[bone].rotation = match track {
                Some(track) if track.interpolation() == Interpolation::Linear => self.slerp(bone, track),
                Some(track) => sample_track_near(track, self.time, &mut self.hints[bone][1]),
                None => self.skeleton.bone(bone).rest.rotation,
            };
        }
        self.values[bone].rotation
    }

    pub fn scale(&mut self, bone: usize) -> DVec3 {
        if self.fresh(bone, SCALE) {
            let track = self.tracks[bone].and_then(|t| t.scale.as_ref());
            self.values[bone].scale = match track {
                Some(track) => sample_track_near(track, self.time, &mut self.hints[bone][2]),
                None => self.skeleton.bone(bone).rest.scale,
            };
        }
        self.values[bone].scale
    }

    /// The stretch rotation of the bone's local transform (clips do not animate it: the rest's).
    pub fn stretch(&self, bone: usize) -> DQuat {
        self.values[bone].stretch
    }

    /// Every channel of the bone.
    pub fn local(&mut self, bone: usize) -> Transform {
        Transform {
            translation: self.translation(bone),
            rotation: self.rotation(bone),
            scale: self.scale(bone),
            stretch: self.stretch(bone),
        }
    }

    /// A linear rotation track at this time, as [`sample_track_near`] samples it, keeping the key interval's
    /// [`Slerp`] for the next times that fall in it.
    fn slerp(&mut self, bone: usize, track: &Track<Quat>) -> DQuat {
        match Span::locate_near(track.times(), self.time, &mut self.hints[bone][1]) {
            Span::Key(k) => key_value(track, k),
            Span::Between { k, t } => {
                let (interval, slerp) = &mut self.slerps[bone];
                if *interval != k {
                    (*interval, *slerp) = (k, Slerp::new(key_value(track, k), key_value(track, k + 1)));
                }
                slerp.at(t)
            }
        }
    }

    /// Whether `channel` of `bone` still has to be sampled at this time; marks it sampled.
    fn fresh(&mut self, bone: usize, channel: u8) -> bool {
        let fresh = self.sampled[bone] & channel == 0;
        self.sampled[bone] |= channel;
        fresh
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::sample_clip;
    use crate::import::stress_rig;

    #[test]
    fn channels_read_singly_match_the_sampled_clip() {
        let rig = stress_rig(30, 120, 4);
        let (skeleton, clip) = (&rig.skeleton, &rig.clips[0]);
        let mut cursor = ClipCursor::new(skeleton, clip);
        let mut pose = Vec::new();
        // Forward in uneven steps, then back: values never depend on the order or on what was read before.
        let times = (0..90).map(|i| f64::from(i) * 0.047).chain([3.9, 0.2, -1.0, 10.0, 1.234]);
        for (i, time) in times.enumerate() {
            sample_clip(skeleton, clip, time, &mut pose);
            cursor.seek(time);
            for bone in (0..skeleton.len()).filter(|b| (b + i) % 3 != 0) {
                assert_eq!(cursor.rotation(bone), pose[bone].rotation, "rotation of {bone} at {time}");
                assert_eq!(cursor.local(bone), pose[bone], "bone {bone} at {time}");
            }
        }
    }
}
