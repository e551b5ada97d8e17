//! One memory budget for the process: readers and verbs estimate what they
//! will allocate before allocating it, and refuse with [`Error::Memory`]
//! (one line naming the estimate) when it is over the budget.
//!
//! The default budget is [`DEFAULT_FRACTION`] of the memory this process may
//! use: the machine's physical memory (`MemTotal` in `/proc/meminfo`), or
//! the address-space or data-segment limit (`ulimit -v`, `ulimit -d`) when
//! that is smaller; 4 GiB when none of them can be read. The CLI's
//! `--max-memory` sets it ([`set_memory_budget`]).
//!
//! The estimates are of the largest buffers (decoded samples, inflated
//! streams, refined levels), not of every allocation, so a run may use
//! somewhat more than the budget; the point is that no input can make a
//! run allocate without bound.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// The default budget as a fraction of the memory the process may use.
pub const DEFAULT_FRACTION: f64 = 0.5;

/// The budget in bytes (0: not set yet, the default applies).
static BUDGET: AtomicU64 = AtomicU64::new(0);

/// The budget in bytes: the one set by [`set_memory_budget`], else the default.
pub fn memory_budget() -> u64 {
    match BUDGET.load(Ordering::Relaxed) {
        0 => {
            let default = (DEFAULT_FRACTION * usable_memory() as f64) as u64;
            BUDGET.store(default.max(1), Ordering::Relaxed);
            default.max(1)
        }
        b => b,
    }
}

/// Sets the budget (bytes, at least 1).
pub fn set_memory_budget(bytes: u64) {
    BUDGET.store(bytes.max(1), Ordering::Relaxed);
}

/// `Ok` when `bytes` fits the budget, else [`Error::Memory`] naming `what`.
///
/// ```
/// use subdyn::memory::check_memory;
/// assert!(check_memory("a small buffer", 1024).is_ok());
/// let err = check_memory("decoding 200 pages of 8192 × 8192", u64::MAX).unwrap_err();
/// assert!(err.to_string().contains("over the memory budget"));
/// ```
pub fn check_memory(what: &str, bytes: u64) -> Result<()> {
    let budget = memory_budget();
    if bytes <= budget {
        return Ok(());
    }
    Err(Error::Memory {
        what: what.to_string(),
        bytes,
        budget,
    })
}

/// Parses a size: a number of bytes with an optional unit `k`, `M`, `G` or
/// `T` (decimal, any case, an optional trailing `B`), for `--max-memory`.
///
/// ```
/// use subdyn::memory::parse_memory_size;
/// assert_eq!(parse_memory_size("1500").unwrap(), 1500);
/// assert_eq!(parse_memory_size("2G").unwrap(), 2_000_000_000);
/// assert_eq!(parse_memory_size("1.5 GB").unwrap(), 1_500_000_000);
/// assert!(parse_memory_size("0").is_err());
/// assert!(parse_memory_size("lots").is_err());
/// ```
pub fn parse_memory_size(text: &str) -> Result<u64> {
    let t = text.trim();
    let t = t.strip_suffix(['b', 'B']).unwrap_or(t).trim_end();
    let (number, scale) = match t.chars().last().map(|c| c.to_ascii_lowercase()) {
        Some('k') => (&t[..t.len() - 1], 1e3),
        Some('m') => (&t[..t.len() - 1], 1e6),
        Some('g') => (&t[..t.len() - 1], 1e9),
        Some('t') => (&t[..t.len() - 1], 1e12),
        _ => (t, 1.0),
    };
    match number.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x * scale >= 1.0 && x * scale < 1.8e19 => Ok((x * scale) as u64),
        _ => Err(Error::input(format!(
            "memory size {text:?}: expected a positive number of bytes, optionally with k, M, G or T (such as 2G)"
        ))),
    }
}

/// `count × each` bytes, saturating (an estimate that overflows is over any budget).
pub fn bytes_of(count: u64, each: u64) -> u64 {
    count.saturating_mul(each)
}

/// `bytes` as `1.5 GB` / `320 MB` / `12 kB` (decimal units).
pub fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.0} kB", (b / 1e3).max(1.0))
    }
}

/// The memory this process may use: physical memory, or a smaller
/// address-space or data limit.
fn usable_memory() -> u64 {
    let physical = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
            let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kb.saturating_mul(1024))
        });
    let limits = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .map(|text| {
            text.lines()
                .filter(|l| l.starts_with("Max address space") || l.starts_with("Max data size"))
                .filter_map(|l| l.split_whitespace().nth(3)?.parse::<u64>().ok())
                .min()
        });
    [physical, limits.flatten()]
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(4 << 30)
}
