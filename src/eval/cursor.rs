//! One bone's channels in a clip, read one at a time: a whole-clip analysis reads a bone's rotation only where its
//! parent stretches unevenly, and never its translation unless it plots the bone.

use glam::{DQuat, DVec3, Quat};

use super::sample::{Span, key_value, sample_track_near};
use crate::math::Slerp;
use crate::model::{BoneTracks, Clip, Interpolation, Skeleton, Track, Transform};

/// Samples the channels of one bone with the values of [`super::sample_clip`], fastest at increasing times: each
/// channel starts its key search where the last one ended (as [`super::Pose`] does), and a linear rotation keeps
/// the [`Slerp`] of its current key interval.
#[derive(Clone, Debug)]
pub struct BoneCursor<'a> {
    rest: Transform,
    tracks: Option<&'a BoneTracks>,
    /// Where the translation, rotation, scale and stretch keys were found last.
    hints: [usize; 4],
    /// The last rotation key interval and its slerp.
    slerp: (usize, Slerp),
}

impl<'a> BoneCursor<'a> {
    pub fn new(skeleton: &Skeleton, clip: &'a Clip, bone: usize) -> Self {
        BoneCursor {
            rest: skeleton.bone(bone).rest,
            tracks: clip.tracks_of(bone),
            hints: [0; 4],
            slerp: (usize::MAX, Slerp::new(DQuat::IDENTITY, DQuat::IDENTITY)),
        }
    }

    pub fn translation(&mut self, time: f64) -> DVec3 {
        match self.tracks.and_then(|t| t.translation.as_ref()) {
            Some(track) => sample_track_near(track, time, &mut self.hints[0]),
            None => self.rest.translation,
        }
    }

    #[inline]
    pub fn rotation(&mut self, time: f64) -> DQuat {
        match self.tracks.and_then(|t| t.rotation.as_ref()) {
            Some(track) if track.interpolation() == Interpolation::Linear => self.slerp(track, time),
            Some(track) => sample_track_near(track, time, &mut self.hints[1]),
            None => self.rest.rotation,
        }
    }

    pub fn scale(&mut self, time: f64) -> DVec3 {
        match self.tracks.and_then(|t| t.scale.as_ref()) {
            Some(track) => sample_track_near(track, time, &mut self.hints[2]),
            None => self.rest.scale,
        }
    }

    /// The stretch rotation of the local transform: the clip's where it sets one, else the rest's.
    pub fn stretch(&mut self, time: f64) -> DQuat {
        match self.tracks.and_then(|t| t.stretch.as_ref()) {
            Some(track) => sample_track_near(track, time, &mut self.hints[3]),
            None => self.rest.stretch,
        }
    }

    /// Every channel.
    pub fn local(&mut self, time: f64) -> Transform {
        Transform {
            translation: self.translation(time),
            rotation: self.rotation(time),
            scale: self.scale(time),
            stretch: self.stretch(time),
        }
    }

    /// A linear rotation track at `time` as [`sample_track_near`] samples it, the key interval's [`Slerp`] kept
    /// for the next times that fall in it.
    #[inline]
    fn slerp(&mut self, track: &Track<Quat>, time: f64) -> DQuat {
        match Span::locate_near(track.times(), time, &mut self.hints[1]) {
            Span::Key(k) => key_value(track, k),
            Span::Between { k, t } => {
                let (interval, slerp) = &mut self.slerp;
                if *interval != k {
                    (*interval, *slerp) = (k, Slerp::new(key_value(track, k), key_value(track, k + 1)));
                }
                slerp.at(t)
            }
        }
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
        let mut cursors: Vec<BoneCursor> = (0..skeleton.len()).map(|b| BoneCursor::new(skeleton, clip, b)).collect();
        let mut pose = Vec::new();
        // Forward in uneven steps, then back and outside the clip: values never depend on the order.
        let times = (0..90).map(|i| f64::from(i) * 0.047).chain([3.9, 0.2, -1.0, 10.0, 1.234]);
        for time in times {
            sample_clip(skeleton, clip, time, &mut pose);
            for (bone, cursor) in cursors.iter_mut().enumerate() {
                assert_eq!(cursor.rotation(time), pose[bone].rotation, "rotation of {bone} at {time}");
                assert_eq!(cursor.local(time), pose[bone], "bone {bone} at {time}");
            }
        }
    }
}
