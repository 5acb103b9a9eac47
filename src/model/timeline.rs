//! A clip's stretch of its file's clock ([`Span`]), how a time reads as a frame ([`At`]), and which times to sample
//! a clip at: every frame of a rate and every key time, with a bound for long, sparse clips.
//!
//! A clip may legally span millions of frames with a few dozen keys (Maya's long-keyframe tests: 41 keys over
//! ±166,666 s). Sampling every frame of such a clip costs memory and time out of all proportion to its content, so
//! when the frames exceed a limit, the grid is thinned where keys are sparse: every key time stays, a gap between two
//! keys keeps all its frames when it has at most [`SAMPLES_PER_SPARSE_GAP`] of them, and that many evenly spaced
//! times otherwise. The result is bounded by the number of keys, whatever the span.

/// Times closer than this are one sample: a microsecond, or single precision's rounding at that time when larger.
/// Key times stored as `f32` (glTF) miss the frame grid by up to half an `f32` step (4e-6 s at 100 s); counted apart,
/// a 6,000-key clip at 60 Hz would be sampled twice as often as it has frames.
const SAME_TIME: f64 = 1e-6;

/// The most frames of a rate a whole-clip pass visits at every one of; past it, the grid is thinned between sparse
/// keys as the module says.
pub const MAX_FRAMES: usize = 1 << 20;

/// How many times a long gap between two keys is sampled at when the grid is thinned.
pub const SAMPLES_PER_SPARSE_GAP: usize = 64;

/// Where a clip lies on its file's clock, in seconds: from its first frame to its last. Each format's own clock is
/// kept (a glTF key written at 1/24 s is at 1/24 s, a USD time code `c` at `c / timeCodesPerSecond`, an FBX key at
/// its stored time), so two exports of one scene read the same times where their exporters wrote the same times.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Span {
    pub start: f64,
    pub end: f64,
}

impl Span {
    /// The span from `start` to `end`; an empty one at `start` where `end` comes before it (or either is not finite).
    pub fn new(start: f64, end: f64) -> Span {
        let start = if start.is_finite() { start } else { 0.0 };
        Span { start, end: if end.is_finite() { end.max(start) } else { start } }
    }

    /// The span at one time.
    pub fn at(time: f64) -> Span {
        Span::new(time, time)
    }

    /// Seconds from start to end.
    pub fn length(&self) -> f64 {
        self.end - self.start
    }

    /// `time` held within the span.
    pub fn clamp(&self, time: f64) -> f64 {
        time.clamp(self.start, self.end)
    }

    /// The same span `by` seconds later.
    pub fn shifted(self, by: f64) -> Span {
        Span { start: self.start + by, end: self.end + by }
    }

    /// The times both spans hold, `None` where they do not meet.
    pub fn overlap(self, other: Span) -> Option<Span> {
        let (start, end) = (self.start.max(other.start), self.end.min(other.end));
        (start <= end).then_some(Span { start, end })
    }
}

/// A time as people read it beside a frame rate: `0.5833 s (frame 14)`, the frame `time × rate` on the clip's own
/// clock (whole where the time is within a thousandth of a frame of one, else to a tenth); the seconds alone without
/// a rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct At {
    pub time: f64,
    pub rate: Option<f64>,
}

impl At {
    /// The frame `time` falls on at the rate, where there is a usable rate.
    pub fn frame(&self) -> Option<f64> {
        let rate = self.rate.filter(|r| r.is_finite() && *r > 0.0)?;
        let frame = self.time * rate;
        frame.is_finite().then_some(frame)
    }
}

impl std::fmt::Display for At {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.4} s", self.time)?;
        match self.frame() {
            Some(frame) => write!(f, " (frame {})", frames(frame)),
            None => Ok(()),
        }
    }
}

/// A number of frames as people read it: whole where it is within a thousandth of a whole number, else to a tenth.
pub fn frames(count: f64) -> String {
    let whole = count.round();
    if (count - whole).abs() < 1e-3 { format!("{}", whole + 0.0) } else { format!("{count:.1}") }
}

/// Sorted `times` with the midpoint between each two beside them: where something keyed at `times` strays most.
pub fn with_midpoints(times: &[f64]) -> Vec<f64> {
    let mut all = Vec::with_capacity(2 * times.len());
    for pair in times.windows(2) {
        all.extend([pair[0], 0.5 * (pair[0] + pair[1])]);
    }
    all.extend(times.last());
    all
}

/// The sorted, distinct times to sample, and whether some frames were left out.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleTimes {
    pub times: Vec<f64>,
    /// How many frames of the rate the span holds (whether or not all are in `times`).
    pub frames: f64,
    /// Whether long gaps between keys were sampled at [`SAMPLES_PER_SPARSE_GAP`] times instead of every frame.
    pub thinned: bool,
}

/// Every frame `k / rate` in `[begin, end]`, both ends, and every key time in between (keys outside are ignored),
/// sorted and without near-duplicates; thinned as the module says when the frames exceed `max_frames`.
pub fn sample_times(
    keys: impl IntoIterator<Item = f64>,
    begin: f64,
    end: f64,
    rate: f64,
    max_frames: usize,
) -> SampleTimes {
    let mut anchors: Vec<f64> = keys.into_iter().filter(|t| (begin..=end).contains(t)).collect();
    anchors.push(begin);
    anchors.push(end);
    sort_distinct(&mut anchors);
    let usable_rate = rate.is_finite() && rate > 0.0;
    let (first, last) =
        if usable_rate { ((begin * rate - SAME_TIME).ceil(), (end * rate + SAME_TIME).floor()) } else { (1.0, 0.0) };
    let frames = if last >= first { last - first + 1.0 } else { 0.0 };
    let frame = |k: f64| (k / rate).clamp(begin, end);
    let thinned = frames > max_frames as f64;
    let mut times = Vec::new();
    if !thinned {
        times.extend((0..frames as u64).map(|k| frame(first + k as f64)));
    } else {
        for gap in anchors.windows(2) {
            let (a, b) = (gap[0], gap[1]);
            let (from, to) = ((a * rate).floor() + 1.0, (b * rate).ceil() - 1.0);
            let inside = if to >= from { to - from + 1.0 } else { 0.0 };
            if inside <= SAMPLES_PER_SPARSE_GAP as f64 {
                times.extend((0..inside as u64).map(|k| frame(from + k as f64)));
            } else {
                let step = (b - a) / (SAMPLES_PER_SPARSE_GAP + 1) as f64;
                times.extend((1..=SAMPLES_PER_SPARSE_GAP).map(|k| a + step * k as f64));
            }
        }
    }
    SampleTimes { times: keep_anchors(anchors, times), frames, thinned }
}

/// Sorts `times` and keeps the first of each run closer than [`SAME_TIME`] (or an `f32` step there).
fn sort_distinct(times: &mut Vec<f64>) {
    times.sort_by(f64::total_cmp);
    times.dedup_by(|later, earlier| same_time(*earlier, *later));
}

/// Whether two sorted times count as one.
fn same_time(earlier: f64, later: f64) -> bool {
    later - earlier < SAME_TIME.max(later.abs() * f64::from(f32::EPSILON))
}

/// `anchors` (sorted, distinct) and `others` in one sorted list where a time of `others` as good as equal to an
/// anchor gives way to it: a stepped key jumps exactly at its own time, so the frame a hair before it must not
/// stand in for it.
fn keep_anchors(anchors: Vec<f64>, mut others: Vec<f64>) -> Vec<f64> {
    others.retain(|&t| {
        let next = anchors.partition_point(|&a| a < t);
        let near = |i: usize| anchors.get(i).is_some_and(|&a| same_time(a.min(t), a.max(t)));
        !(near(next) || next.checked_sub(1).is_some_and(near))
    });
    let mut times = anchors;
    times.extend(others);
    sort_distinct(&mut times);
    times
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn midpoints_lie_between_the_times_in_order() {
        assert_eq!(with_midpoints(&[0.0, 1.0, 3.0]), [0.0, 0.5, 1.0, 2.0, 3.0]);
        assert_eq!(with_midpoints(&[2.0]), [2.0]);
        assert!(with_midpoints(&[]).is_empty());
    }

    #[test]
    fn spans_meet_shift_and_hold() {
        let a = Span::new(1.0 / 24.0, 2.0);
        assert_eq!(a.length(), 2.0 - 1.0 / 24.0);
        assert_eq!(a.shifted(-1.0 / 24.0), Span::new(0.0, 2.0 - 1.0 / 24.0));
        assert_eq!(a.overlap(Span::new(0.0, 1.0)), Some(Span::new(1.0 / 24.0, 1.0)));
        assert_eq!(a.overlap(Span::new(3.0, 4.0)), None);
        assert_eq!(a.clamp(0.0), 1.0 / 24.0);
        assert_eq!(Span::new(2.0, 1.0), Span::at(2.0), "a reversed span is empty at its start");
        assert_eq!(Span::new(f64::NAN, f64::INFINITY), Span::at(0.0));
    }

    #[test]
    fn times_read_with_their_frames() {
        let at = |time, rate| At { time, rate }.to_string();
        assert_eq!(at(14.0 / 24.0, Some(24.0)), "0.5833 s (frame 14)");
        assert_eq!(at(0.55, Some(24.0)), "0.5500 s (frame 13.2)");
        assert_eq!(at(-1.0 / 30.0, Some(30.0)), "-0.0333 s (frame -1)");
        assert_eq!(at(0.0, Some(30.0)), "0.0000 s (frame 0)");
        assert_eq!(at(0.5, None), "0.5000 s");
        assert_eq!(at(0.5, Some(0.0)), "0.5000 s");
        // A single-precision key time a hair off its frame still reads as the frame.
        assert_eq!(at(f64::from((11.0f64 / 24.0) as f32), Some(24.0)), "0.4583 s (frame 11)");
    }

    #[test]
    fn every_frame_and_key_when_within_the_limit() {
        let s = sample_times([0.25, 0.5, 3.0], 0.0, 1.0, 2.0, 100);
        assert_eq!(s.times, [0.0, 0.25, 0.5, 1.0]);
        assert_eq!(s.frames, 3.0);
        assert!(!s.thinned);
    }

    #[test]
    fn frames_never_fall_outside_the_span() {
        // A span that starts one tick after a frame: the frame before it is not sampled, the start is.
        let tick = 1.0 / 46_186_158_000.0;
        let begin = -1.0 / 24.0 + tick;
        let s = sample_times([], begin, 1.0 / 24.0, 24.0, 100);
        assert_eq!(s.times[0], begin);
        assert!(s.times.iter().all(|&t| (begin..=1.0 / 24.0).contains(&t)), "{:?}", s.times);
        assert_eq!(s.times.len(), 3, "{:?}", s.times);
    }

    #[test]
    fn long_sparse_spans_keep_every_key_and_a_bounded_number_between() {
        // 10 million frames at 30 fps, keys at the ends, in the middle, and a dense run of 5 frames.
        let keys = [-166_666.0, 0.0, 1.0 / 30.0, 2.0 / 30.0, 3.0 / 30.0, 4.0 / 30.0, 166_666.0];
        let s = sample_times(keys, -166_666.0, 166_666.0, 30.0, 1 << 20);
        assert!(s.thinned);
        assert_eq!(s.frames, 10_000_000.0 - 40.0 + 1.0);
        for key in keys {
            assert!(s.times.iter().any(|&t| (t - key).abs() < 1e-12), "key {key} kept");
        }
        // Two long gaps get 64 times each; the four gaps of the dense run have no frame inside.
        assert_eq!(s.times.len(), keys.len() + 2 * SAMPLES_PER_SPARSE_GAP);
        assert!(s.times.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn a_short_gap_keeps_its_frames_when_thinned() {
        // Keys at 0 and 1 s and at 100 s, 1 Hz: frames 2..99 are too many for the gap, frames of 0..1 none.
        let s = sample_times([0.0, 0.5, 100.0], 0.0, 100.0, 10.0, 10);
        assert!(s.thinned);
        // 0 → 0.5: frames 0.1..0.4 (4), 0.5 → 100: 64 evenly spaced.
        assert_eq!(s.times.len(), 3 + 4 + SAMPLES_PER_SPARSE_GAP);
    }

    #[test]
    fn a_key_a_hair_after_a_frame_stands_for_it() {
        // 11/24 s as an f32 key time lies 1e-8 s after the frame: the key's own time is sampled.
        let key = f64::from((11.0f64 / 24.0) as f32);
        let s = sample_times([key], 0.0, 1.0, 24.0, 100);
        assert!(s.times.contains(&key) && !s.times.contains(&(11.0 / 24.0)), "{:?}", s.times);
        assert_eq!(s.times.len(), 25);
    }

    #[test]
    fn no_rate_gives_the_anchors() {
        assert_eq!(sample_times([0.5], 0.0, 1.0, 0.0, 10).times, [0.0, 0.5, 1.0]);
    }

    #[test]
    fn single_precision_key_times_meet_the_frame_grid() {
        // 6,000 keys at 60 Hz stored as f32 (glTF's key times), sampled at 60 Hz: one sample per frame.
        let keys: Vec<f64> = (0..6000).map(|k| f64::from((k as f64 / 60.0) as f32)).collect();
        let end = keys[keys.len() - 1];
        let s = sample_times(keys.iter().copied(), 0.0, end, 60.0, 1 << 20);
        assert_eq!(s.times.len(), 6000, "not {} (key times and frames counted apart)", s.times.len());
    }
}
