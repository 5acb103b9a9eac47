//! A crossfade: from some time on, the end of the playing clip blends into the start of another over a
//! chosen duration, computed on the fly from both clips (no frames are stored).

use crate::model::Choice;

/// How the incoming clip's weight rises over the fade.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FadeCurve {
    /// Constant speed: the weight is the fraction of the fade done.
    #[default]
    Linear,
    /// Smoothstep `3s² − 2s³`: starts and ends without a jump in speed.
    Smooth,
}

impl Choice for FadeCurve {
    const ALL: &'static [FadeCurve] = &[FadeCurve::Linear, FadeCurve::Smooth];

    fn id(self) -> &'static str {
        match self {
            FadeCurve::Linear => "linear",
            FadeCurve::Smooth => "smooth",
        }
    }

    fn description(self) -> &'static str {
        match self {
            FadeCurve::Linear => "constant speed: the weight is the fraction of the fade done",
            FadeCurve::Smooth => "smoothstep 3s² − 2s³: starts and ends without a jump in speed",
        }
    }
}

impl FadeCurve {
    /// The weight at fraction `s` of the fade (clamped to `[0, 1]`).
    pub fn weight(self, s: f64) -> f64 {
        let s = super::unit_weight(s);
        match self {
            FadeCurve::Linear => s,
            FadeCurve::Smooth => s * s * (3.0 - 2.0 * s),
        }
    }
}

/// A transition into clip `clip` starting at `at` seconds and lasting `duration` seconds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Crossfade {
    /// Index of the incoming clip in the rig.
    pub clip: usize,
    pub at: f64,
    pub duration: f64,
    pub curve: FadeCurve,
}

impl Crossfade {
    /// The incoming clip's weight at `time`: 0 before `at`, rising along the curve, 1 from `at + duration` on (a
    /// cut at `at` when the duration is not positive).
    pub fn weight(&self, time: f64) -> f64 {
        match (time.partial_cmp(&self.at), self.duration > 0.0) {
            (None | Some(std::cmp::Ordering::Less), _) => 0.0,
            (_, false) => 1.0,
            (_, true) => self.curve.weight((time - self.at) / self.duration),
        }
    }

    /// The incoming clip's own time at `time`: it starts from its beginning at `at`.
    pub fn incoming_time(&self, time: f64) -> f64 {
        (time - self.at).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_over_the_fade() {
        let fade = Crossfade { clip: 1, at: 1.0, duration: 0.5, curve: FadeCurve::Linear };
        assert_eq!(
            [fade.weight(0.9), fade.weight(1.0), fade.weight(1.125), fade.weight(1.5), fade.weight(9.0)],
            [0.0, 0.0, 0.25, 1.0, 1.0]
        );
        // Smoothstep at s = 0.25: 0.0625·2.5 = 0.15625; symmetric about the middle.
        let smooth = Crossfade { curve: FadeCurve::Smooth, ..fade };
        assert_eq!(smooth.weight(1.125), 0.15625);
        assert_eq!(smooth.weight(1.25), 0.5);
        assert_eq!(smooth.weight(1.375), 1.0 - 0.15625);
        assert_eq!(fade.incoming_time(1.2), 0.19999999999999996);
        assert_eq!(fade.incoming_time(0.2), 0.0);
        let cut = Crossfade { duration: 0.0, ..fade };
        assert_eq!([cut.weight(0.99), cut.weight(1.0)], [0.0, 1.0]);
        assert_eq!(fade.weight(f64::NAN), 0.0);
        assert_eq!(Crossfade { duration: f64::NAN, ..fade }.weight(2.0), 1.0);
    }
}
