//! The memory budget: how much memory one file may make bonescope use.
//!
//! A small file may legally describe huge work (2,000 channels sharing one sampler of 100,000 keys, 20,000 nodes
//! showing one mesh of 100,000 vertices). An allocation that fails aborts the process, so each importer estimates
//! what a file needs before it allocates and refuses a file beyond the budget with one line naming the figure. The
//! budget is half the machine's memory (or of the control group's), and at most a quarter of the process's
//! address-space limit (`RLIMIT_AS`, which also counts the space threads and allocators reserve and never touch);
//! `--max-memory` sets it ([`set_limit`]).

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

use super::failure::{Failure, Result};

/// What an evaluated bone costs beyond its tracks, all told: the bone, its place in every pose (local and model
/// matrices, their decomposition), its findings and its share of a printed report (`inspect` prints every bone).
pub const BONE_BYTES: u64 = 4 << 10;

/// The budget set by `--max-memory`; 0 for the machine's default.
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// Sets the budget (`None`: the machine's default).
pub fn set_limit(bytes: Option<u64>) {
    LIMIT.store(bytes.unwrap_or(0), Ordering::Relaxed);
}

/// The budget set, if one was (`None`: the machine's default).
pub fn explicit_limit() -> Option<u64> {
    Some(LIMIT.load(Ordering::Relaxed)).filter(|&set| set != 0)
}

/// The budget, in bytes.
pub fn limit() -> u64 {
    match LIMIT.load(Ordering::Relaxed) {
        0 => machine_default(),
        set => set,
    }
}

/// Refuses a need of `bytes` beyond the budget, naming `place` and what the memory would be for.
pub(super) fn check(bytes: u64, place: Option<&str>, what: impl FnOnce() -> String) -> Result<()> {
    let limit = limit();
    if bytes <= limit {
        return Ok(());
    }
    let message = format!("needs ~{} for {}; the limit is {} (--max-memory)", size(bytes), what(), size(limit));
    Err(Failure { place: place.map(str::to_owned), message })
}

/// Half the machine's memory, or of its control group's limit, and at most a quarter of the address-space limit;
/// read once.
fn machine_default() -> u64 {
    static DEFAULT: OnceLock<u64> = OnceLock::new();
    *DEFAULT.get_or_init(|| {
        const UNKNOWN_MEMORY: u64 = 8 << 30;
        let physical = physical_memory().unwrap_or(UNKNOWN_MEMORY);
        let group = control_group_limit().unwrap_or(u64::MAX);
        let address_space = address_space_limit().unwrap_or(u64::MAX);
        (physical.min(group) / 2).min(address_space / 4)
    })
}

/// `MemTotal` of `/proc/meminfo` (Linux).
fn physical_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// The cgroup v2 memory limit of this process's group, when it has one.
fn control_group_limit() -> Option<u64> {
    std::fs::read_to_string("/sys/fs/cgroup/memory.max").ok()?.trim().parse().ok()
}

/// The soft `RLIMIT_AS` of this process (`Max address space` in `/proc/self/limits`), when it has one.
fn address_space_limit() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
    line.trim_start_matches("Max address space").split_whitespace().next()?.parse().ok()
}

/// Bytes for people: `712 MiB`, `24 GiB`.
pub fn size(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 || value >= 10.0 {
        format!("{value:.0} {}", UNITS[unit])
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// A size as `--max-memory` takes it: bytes, or a number with `K`, `M`, `G`, `T` (powers of 1024, `KiB`, `KB`
/// and `k` read alike), e.g. `512M`, `1.5GiB`.
pub fn parse_size(text: &str) -> std::result::Result<u64, String> {
    let text = text.trim();
    let split = text.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let shift = match unit.trim().to_ascii_lowercase().trim_end_matches("ib").trim_end_matches('b') {
        "" => 0,
        "k" => 10,
        "m" => 20,
        "g" => 30,
        "t" => 40,
        _ => return Err(format!("`{text}`: expected a size such as 512M or 8GiB")),
    };
    let value: f64 = number.parse().map_err(|_| format!("`{text}`: expected a size such as 512M or 8GiB"))?;
    let bytes = value * (1u64 << shift) as f64;
    if bytes >= 1.0 && bytes < u64::MAX as f64 {
        Ok(bytes as u64)
    } else {
        Err(format!("`{text}`: the limit must be at least one byte and below 16 EiB"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_and_print() {
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("8GiB"), Ok(8 << 30));
        assert_eq!(parse_size("1.5 GB"), Ok(3 << 29));
        assert_eq!(parse_size("4096"), Ok(4096));
        assert_eq!(parse_size("2k"), Ok(2048));
        assert!(parse_size("0").is_err() && parse_size("lots").is_err() && parse_size("5X").is_err());
        assert_eq!(size(712 << 20), "712 MiB");
        assert_eq!(size(24 << 30), "24 GiB");
        assert_eq!(size(3 << 29), "1.5 GiB");
        assert_eq!(size(100), "100 bytes");
    }

    #[test]
    fn the_default_is_a_share_of_the_machine() {
        let physical = physical_memory().expect("/proc/meminfo on Linux");
        assert!(machine_default() <= physical / 2 && machine_default() > 0);
    }
}
