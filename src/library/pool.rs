//! Many files, several at a time, reported in order: a library of thousands of exports is scanned with a bounded
//! number of files in flight (memory follows the largest files being read, not the library), and each result is
//! handed on as soon as it and every file before it are done, so reports stream in the files' sorted order whatever
//! the thread timing.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

/// How many files per thread are in flight at most.
const FILES_PER_JOB: usize = 2;

/// Runs `work` on `paths` with `jobs` threads (their own pool; each file's own analysis shares it), and calls
/// `done` with each path and its result in the paths' order. Files not yet started when `stop` is set are skipped;
/// how many were done.
pub fn in_order<T: Send>(
    paths: &[PathBuf],
    jobs: usize,
    work: impl Fn(&Path) -> T + Sync,
    mut done: impl FnMut(&Path, T),
    stop: &AtomicBool,
) -> usize {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs.max(1)).build();
    let run = |window: &[PathBuf]| -> Vec<Option<T>> {
        let each = |path: &PathBuf| (!stop.load(Ordering::Relaxed)).then(|| work(path));
        match &pool {
            Ok(pool) => pool.install(|| window.par_iter().map(each).collect()),
            // A pool that cannot be built (no threads left): one file after another.
            Err(_) => window.iter().map(each).collect(),
        }
    };
    let mut count = 0;
    for window in paths.chunks(jobs.max(1) * FILES_PER_JOB) {
        for (path, result) in window.iter().zip(run(window)) {
            let Some(result) = result else { return count };
            done(path, result);
            count += 1;
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_in_the_paths_order_whatever_the_timing() {
        let paths: Vec<PathBuf> = (0..20).map(|i| PathBuf::from(format!("{i:02}"))).collect();
        let never = AtomicBool::new(false);
        let mut seen = Vec::new();
        // Earlier files take longer: finished out of order, reported in order.
        let work = |p: &Path| {
            let i: u64 = p.to_string_lossy().parse().unwrap();
            std::thread::sleep(std::time::Duration::from_millis(20 - i));
            i
        };
        let count = in_order(&paths, 4, work, |_, i| seen.push(i), &never);
        assert_eq!((count, seen), (20, (0..20).collect::<Vec<u64>>()));
    }

    #[test]
    fn a_stop_skips_the_files_not_started() {
        let paths: Vec<PathBuf> = (0..20).map(|i| PathBuf::from(i.to_string())).collect();
        let stop = AtomicBool::new(false);
        let mut seen = 0;
        let count = in_order(&paths, 1, |_| stop.store(true, Ordering::Relaxed), |_, ()| seen += 1, &stop);
        assert!(count < 20 && count == seen, "{count}");
    }
}
