//! Time: 3ds Max's ticks, and the sync of two cycles of different lengths (a walk blended with a run).

/// 3ds Max's time unit: 1/4800 s, so that the frame periods at 24, 25, 30, 50 and 60 fps are whole numbers of ticks.
pub const TICKS_PER_SECOND: f64 = 4800.0;

/// Two cycles played at one normalised time, as a walk–run blend plays them: with clip lengths `T1`, `T2` and blend
/// factor `a`, the blended cycle lasts `(T2 − T1)·a + T1` and the clips play at rates `T1/len` and `T2/len`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SyncedCycle {
    /// The blended cycle length in seconds.
    pub length: f64,
    /// The playback rates of the two clips (1 when the cycle is empty).
    pub rates: [f64; 2],
    durations: [f64; 2],
}

impl SyncedCycle {
    /// `t1`, `t2`: the clip lengths in seconds (anything but a positive number counts as 0); `a` is clamped to
    /// `[0, 1]` (NaN counts as 0).
    pub fn new(t1: f64, t2: f64, a: f64) -> Self {
        let durations = [t1, t2].map(|t| if t > 0.0 && t.is_finite() { t } else { 0.0 });
        let a = super::unit_weight(a);
        let length = (durations[1] - durations[0]) * a + durations[0];
        let rates = durations.map(|t| if length > 0.0 { t / length } else { 1.0 });
        SyncedCycle { length, rates, durations }
    }

    /// Where `time` (seconds of the blended cycle) falls in the cycle, in `[0, 1)`: the cycle repeats.
    pub fn phase(&self, time: f64) -> f64 {
        if self.length > 0.0 && time.is_finite() { time.rem_euclid(self.length) / self.length } else { 0.0 }
    }

    /// The time of each clip at blended time `time`: the same phase of both, i.e. `rate · time` within a cycle.
    /// (The second clip's normalised time is set to the first's rather than trusting two rates to stay in step,
    /// which rounding would break over many cycles.)
    pub fn clip_times(&self, time: f64) -> [f64; 2] {
        let phase = self.phase(time);
        self.durations.map(|t| phase * t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seeds_walk_run_numbers() {
        // Walk 1.2 s, run 0.8 s, a = 0.25: (0.8 − 1.2)·0.25 + 1.2 = 1.1 s; rates 1.2/1.1 = 1.0909, 0.8/1.1 = 0.7273.
        let cycle = SyncedCycle::new(1.2, 0.8, 0.25);
        assert!((cycle.length - 1.1).abs() < 1e-15);
        assert!((cycle.rates[0] - 1.2 / 1.1).abs() < 1e-15 && (cycle.rates[0] - 1.0909).abs() < 1e-4);
        assert!((cycle.rates[1] - 0.8 / 1.1).abs() < 1e-15 && (cycle.rates[1] - 0.7273).abs() < 1e-4);
        // 0.55 s into the blended cycle is half way: walk at 0.6 s, run at 0.4 s, i.e. rate · time.
        let [walk, run] = cycle.clip_times(0.55);
        assert!((walk - 0.6).abs() < 1e-15 && (run - 0.4).abs() < 1e-15);
        assert!((walk - cycle.rates[0] * 0.55).abs() < 1e-15);
        // The cycle repeats: 1.1 + 0.55 s is the same phase, and so is −0.55 s.
        assert!((cycle.phase(1.65) - 0.5).abs() < 1e-12 && (cycle.phase(-0.55) - 0.5).abs() < 1e-12);
        // The ends of the factor: only walk (a = 0), only run (a = 1).
        assert_eq!(SyncedCycle::new(1.2, 0.8, 0.0).rates, [1.0, 0.8 / 1.2]);
        assert_eq!(SyncedCycle::new(1.2, 0.8, 1.0).length, 0.8);
    }

    #[test]
    fn degenerate_cycles_never_divide_by_zero() {
        let empty = SyncedCycle::new(0.0, 0.0, 0.5);
        assert_eq!((empty.length, empty.rates, empty.clip_times(3.0)), (0.0, [1.0, 1.0], [0.0, 0.0]));
        let nan = SyncedCycle::new(f64::NAN, 1.0, f64::NAN);
        assert_eq!(nan.length, 0.0, "a NaN length counts as 0 and a NaN factor as 0");
        assert_eq!(SyncedCycle::new(1.0, 2.0, 7.0).length, 2.0, "the factor is clamped");
        assert_eq!(SyncedCycle::new(1.0, 2.0, 0.5).clip_times(f64::INFINITY), [0.0, 0.0]);
    }
}
