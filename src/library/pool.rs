//! Many files, several at a time, reported in order: a library of thousands of exports is scanned by a fixed number
//! of workers, each taking the next file as soon as it is done with one (so no core waits for a slow file beside
//! it, and memory follows the few files being read, not the library), and each result is handed on as soon as it
//! and every file before it are done, so reports stream in the files' sorted order whatever the thread timing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

/// Runs `work` on `paths` with `jobs` workers, and calls `done` with each path and its result in the paths'
/// order. The workers are the threads of a pool of their own, which each file's own parallel work (a clip's
/// analysis, an FBX file's sampling) shares, so `jobs` threads run in all. Files not yet started when `stop` is set
/// are skipped; how many were done (in order, up to the first skipped one).
pub fn in_order<T: Send>(
    paths: &[PathBuf],
    jobs: usize,
    work: impl Fn(&Path) -> T + Sync,
    mut done: impl FnMut(&Path, T),
    stop: &AtomicBool,
) -> usize {
    let jobs = jobs.max(1);
    let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(jobs).build() else {
        // A pool that cannot be built (no threads left): one file after another.
        let mut count = 0;
        for path in paths.iter().take_while(|_| !stop.load(Ordering::Relaxed)) {
            done(path, work(path));
            count += 1;
        }
        return count;
    };
    let next = AtomicUsize::new(0);
    let (sender, results) = mpsc::channel();
    let (work, next) = (&work, &next);
    // The scope's own closure runs here, on the caller's thread (which `done` may need), and waits for the workers.
    // One worker per thread of the pool, as a broadcast: a broadcast job runs only on its own thread, so no thread
    // waiting inside one file's parallel work can take up another worker and hold that file back behind it.
    pool.in_place_scope(|scope| {
        scope.spawn_broadcast(move |_, _| {
            while !stop.load(Ordering::Relaxed) {
                let index = next.fetch_add(1, Ordering::Relaxed);
                let Some(path) = paths.get(index) else { break };
                if sender.send(Some((index, work(path)))).is_err() {
                    return;
                }
            }
            // This worker is done (the channel itself closes only when the scope ends).
            let _ = sender.send(None);
        });
        let mut working = pool.current_num_threads();
        let mut waiting = BTreeMap::new();
        let mut count = 0;
        while working > 0 {
            match results.recv() {
                Ok(Some((index, result))) => {
                    waiting.insert(index, result);
                    while let Some(result) = waiting.remove(&count) {
                        done(&paths[count], result);
                        count += 1;
                    }
                }
                Ok(None) => working -= 1,
                Err(_) => break,
            }
        }
        count
    })
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
