//! A fuzzer that runs on stable Rust (cargo-fuzz needs nightly): mutates the shared assets of one format and
//! feeds them to that format's parser (`import::load_bytes_as`), looking for panics, hangs and runaway memory.
//!
//! ```sh
//! cargo run --release --example fuzz_import -- bvh 10       # format (gltf, fbx, bvh, usd), minutes [, seed [, skip]]
//! ```
//!
//! Seeds: every file of that format under `../shared/assets` (and the pose dumps of `assets/dumps`). Each input is a seed with 1–8 mutations: byte
//! flips, inserted or deleted bytes, a 32-bit field set to an extreme value, a number in the text replaced by an
//! absurd one, a range duplicated or spliced in from another seed, a truncation. A panic or an input slower than
//! 5 s is written to `fuzz/artifacts/`, and a watchdog thread writes out an input still running after 20 s (a
//! hang); the run ends with executions, distinct error messages, findings and the peak resident memory.

// Only the shared assets' folder is used here.
#[allow(dead_code)]
#[path = "../benches/support/shared_assets.rs"]
mod shared_assets;

use std::collections::BTreeSet;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use bonescope::import::{Format, Options, load_bytes_as};
use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;

const ABSURD: &[&str] =
    &["4294967296", "4294967295", "-1", "0", "1e308", "-1e308", "nan", "inf", "99999999999999999999", "65536"];

fn mutate(input: &mut Vec<u8>, seeds: &[Vec<u8>], noise: &mut XorShiftRng) {
    for _ in 0..1 + noise.random_range(0..8) {
        let len = input.len();
        match noise.random_range(0..9) {
            0 | 1 if len > 0 => {
                let at = noise.random_range(0..len);
                input[at] ^= 1 << noise.random_range(0..8);
            }
            2 if len > 0 => {
                let at = noise.random_range(0..len);
                input[at] = noise.random::<u8>();
            }
            3 => {
                let at = noise.random_range(0..len + 1);
                input.insert(at, noise.random::<u8>());
            }
            4 if len > 0 => {
                let at = noise.random_range(0..len);
                let end = (at + 1 + noise.random_range(0..64)).min(len);
                input.drain(at..end);
            }
            5 if len >= 4 => {
                // A 32-bit little-endian field (a count, an offset, a length) set to an extreme.
                let at = noise.random_range(0..len - 3);
                let value: u32 = [u32::MAX, 0x8000_0000, 0, 0xFFFF, noise.random::<u32>()][noise.random_range(0..5)];
                input[at..at + 4].copy_from_slice(&value.to_le_bytes());
            }
            6 if len > 0 => {
                // A number in text replaced by an absurd one.
                let at = noise.random_range(0..len);
                if let Some(start) = (at..len).find(|&i| input[i].is_ascii_digit()) {
                    let end = (start..len).find(|&i| !input[i].is_ascii_digit() && input[i] != b'.').unwrap_or(len);
                    let absurd = ABSURD[noise.random_range(0..ABSURD.len())].as_bytes();
                    input.splice(start..end, absurd.iter().copied());
                }
            }
            7 if len > 0 => {
                // A range duplicated, or spliced in from another seed.
                let source = &seeds[noise.random_range(0..seeds.len())];
                let from =
                    if noise.random_range(0..2) == 0 || source.is_empty() { input.clone() } else { source.clone() };
                let start = noise.random_range(0..from.len());
                let end = (start + noise.random_range(0..256)).min(from.len());
                let at = noise.random_range(0..len + 1);
                input.splice(at..at, from[start..end].iter().copied());
            }
            _ => {
                let keep = noise.random_range(0..len + 1);
                input.truncate(keep);
            }
        }
    }
}

fn parse_format(format: &str) -> Format {
    let found = Format::ALL.into_iter().find(|f| f.name().eq_ignore_ascii_case(format));
    let names = Format::ALL.map(|f| f.name().to_lowercase()).join(", ");
    found.unwrap_or_else(|| panic!("unknown format `{format}` ({names})"))
}

/// The seeds of `format`: its small files among the shared assets and the repository's own (the pose dumps bonescope
/// writes).
fn seeds(format: Format) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let shared = std::fs::read_dir(shared_assets::root()).expect("../shared/assets").map(|f| f.unwrap().path());
    let own = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/dumps");
    for folder in shared.chain([own]) {
        if !folder.is_dir() {
            continue;
        }
        for file in std::fs::read_dir(&folder).unwrap() {
            let file = file.unwrap().path();
            let matches = Format::named_by(&file) == Some(format);
            // Large seeds make every execution slow: mutate the small ones (under 2 MB they all are).
            if matches && std::fs::metadata(&file).unwrap().len() < 2_000_000 {
                files.push((file.clone(), std::fs::read(&file).unwrap()));
            }
        }
    }
    files.sort();
    assert!(!files.is_empty(), "no {} seeds", format.name());
    files
}

/// Peak resident memory of this process, from `/proc/self/status` (Linux), in MiB.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let format = args.first().map_or("bvh", String::as_str).to_owned();
    let minutes: f64 = args.get(1).map_or(1.0, |m| m.parse().expect("minutes"));
    let seed: u64 = args.get(2).map_or(0x9e37_79b9_7f4a_7c15, |s| s.parse().expect("seed"));
    let skip: u64 = args.get(3).map_or(0, |s| s.parse().expect("skip"));
    let parsed = parse_format(&format);
    let seeds = seeds(parsed);
    let seed_bytes: Vec<Vec<u8>> = seeds.iter().map(|s| s.1.clone()).collect();
    let artifacts = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/artifacts");
    // A path that names no real folder, so a glTF's external buffers are never found on disk.
    let name = PathBuf::from(format!("/nonexistent/fuzz-input.{format}"));
    std::panic::set_hook(Box::new(|_| {}));

    // The input being parsed, since when, and whether the watchdog is done with it (nothing is parsed yet).
    let running: Arc<Mutex<(Vec<u8>, Instant, bool)>> = Arc::new(Mutex::new((Vec::new(), Instant::now(), true)));
    {
        let running = Arc::clone(&running);
        let (artifacts, format) = (artifacts.clone(), format.clone());
        std::thread::spawn(move || {
            loop {
                std::thread::sleep(Duration::from_secs(1));
                let mut slot = running.lock().unwrap();
                if !slot.2 && slot.1.elapsed() > Duration::from_secs(20) {
                    slot.2 = true;
                    std::fs::create_dir_all(&artifacts).unwrap();
                    let file = artifacts.join(format!("{format}-hang-{}-bytes.bin", slot.0.len()));
                    std::fs::write(&file, &slot.0).unwrap();
                    println!("HANG: an input has run for 20 s (saved to {})", file.display());
                }
            }
        });
    }

    let deadline = Instant::now() + Duration::from_secs_f64(minutes * 60.0);
    let mut noise = XorShiftRng::seed_from_u64(seed);
    for _ in 0..skip {
        let (_, original) = &seeds[noise.random_range(0..seeds.len())];
        mutate(&mut original.clone(), &seed_bytes, &mut noise);
    }
    let (mut executions, mut loaded, mut panics, mut slow) = (skip, 0u64, 0u64, 0u64);
    let mut messages: BTreeSet<String> = BTreeSet::new();
    let mut slowest = (Duration::ZERO, 0usize);
    println!("fuzzing {format} for {minutes} min from {} seeds (seed {seed}, skipping {skip} inputs)", seeds.len());
    while Instant::now() < deadline {
        let (_, original) = &seeds[noise.random_range(0..seeds.len())];
        let mut input = original.clone();
        mutate(&mut input, &seed_bytes, &mut noise);
        *running.lock().unwrap() = (input.clone(), Instant::now(), false);
        let started = Instant::now();
        // Straight to the format's parser: a mutation that breaks the magic still exercises it.
        let result = catch_unwind(AssertUnwindSafe(|| load_bytes_as(parsed, &name, &input, &Options::default())));
        let took = started.elapsed();
        executions += 1;
        if took > slowest.0 {
            slowest = (took, input.len());
        }
        let save = |kind: &str| {
            std::fs::create_dir_all(&artifacts).unwrap();
            let file = artifacts.join(format!("{format}-{kind}-{executions}.bin"));
            std::fs::write(&file, &input).unwrap();
            file
        };
        match result {
            Err(panic) => {
                panics += 1;
                let message = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                println!("PANIC #{panics}: {message} (input saved to {})", save("panic").display());
            }
            Ok(Ok(_)) => loaded += 1,
            Ok(Err(error)) => {
                // Distinct messages, with numbers and quoted words blanked ("line 12", "`x`" count once).
                let mut quoted = false;
                let shape: String = error
                    .message
                    .chars()
                    .filter_map(|c| {
                        if c == '`' {
                            quoted = !quoted;
                            return Some('`');
                        }
                        (!quoted).then_some(if c.is_ascii_digit() { '#' } else { c })
                    })
                    .collect();
                messages.insert(shape);
            }
        }
        if took > Duration::from_secs(5) {
            slow += 1;
            println!("SLOW: {took:?} (input saved to {})", save("slow").display());
        }
        if executions.is_multiple_of(20_000) {
            println!("  {executions} executions, {panics} panics, {} distinct errors", messages.len());
        }
    }
    let executions = executions - skip;
    println!(
        "{format}: {executions} executions in {minutes} min ({:.0}/s), {loaded} loaded, {} distinct error messages, \
         {panics} panics, {slow} inputs over 5 s; slowest {:?} ({} bytes); peak memory {:.0} MiB",
        executions as f64 / (minutes * 60.0),
        messages.len(),
        slowest.0,
        slowest.1,
        peak_memory_mib().unwrap_or(f64::NAN)
    );
    if panics > 0 {
        std::process::exit(1);
    }
}
