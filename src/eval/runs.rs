//! The one way whole-clip work runs in parallel: the sorted times cut into runs of consecutive times, each run
//! worked through by one thread with state of its own (a pose, buffers, a copy of the layers), the runs' results
//! handed back in time order so that merging them gives what one pass in order would.

use rayon::prelude::*;

/// How many runs a long pass is cut into, at most: enough for the threads of a large machine to even out uneven
/// runs.
const RUNS: usize = 16;

/// The fewest times in a run (but the last): shorter runs spend more on setting a worker up than they share out.
const MIN_RUN: usize = 256;

/// The most times in a run: past it a longer run saves nothing on setting a worker up.
const MAX_RUN: usize = 1024;

/// How many consecutive times of `count` one run takes: a multiple of 64 (an analysis keeps one flag per time in
/// 64-bit words, which runs must not share), short enough for every thread to get several runs, and the same on
/// every machine: work whose result depends on where a run starts (a decomposition's search started anew at each
/// run's first time) then gives the same figures, to the last bit, whatever the number of cores.
pub fn run_length(count: usize) -> usize {
    64 * (count.div_ceil(64) / RUNS).clamp(MIN_RUN / 64, MAX_RUN / 64)
}

/// `work` of each run of consecutive `times` (of [`run_length`]), in parallel; the results in time order.
pub fn over_runs<R: Send>(times: &[f64], work: impl Fn(&[f64]) -> R + Sync + Send) -> Vec<R> {
    over_runs_from(times, |_, run| work(run))
}

/// [`over_runs`], each run's work also given the index of its first time.
pub fn over_runs_from<R: Send>(times: &[f64], work: impl Fn(usize, &[f64]) -> R + Sync + Send) -> Vec<R> {
    let length = run_length(times.len());
    times.par_chunks(length).enumerate().map(|(k, run)| work(k * length, run)).collect()
}

/// [`over_runs`] in runs of `length` times: for work that needs runs of its own length.
pub fn over_runs_of<R: Send>(times: &[f64], length: usize, work: impl Fn(&[f64]) -> R + Sync + Send) -> Vec<R> {
    times.par_chunks(length.max(1)).map(work).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_cover_the_times_in_order_in_whole_words() {
        for count in [0, 1, 63, 64, 65, 1000, 100_000, 3_000_000] {
            let times: Vec<f64> = (0..count).map(|k| k as f64).collect();
            let runs = over_runs(&times, |run| run.to_vec());
            assert_eq!(runs.concat(), times, "{count} times");
            let length = run_length(count);
            assert!(length.is_multiple_of(64) && (64..=MAX_RUN).contains(&length), "{length}");
            assert!(runs.iter().rev().skip(1).all(|run| run.len() == length), "only the last run is short");
        }
    }
}
