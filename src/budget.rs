//! The process's memory budget: every step that may allocate in proportion
//! to its input (loading, voxelizing, brushes, renders, dense grids) first
//! estimates its peak and asks [`check`], so that a hostile or careless input
//! gets an error naming the cost instead of an abort or a swapping machine.
//!
//! One number for the whole process, set once at start-up from
//! `--memory-budget` (default [`DEFAULT_BUDGET_BYTES`]); docs/limits.md lists
//! what is checked against it.

use std::sync::atomic::{AtomicU64, Ordering};

/// 4 GiB: enough for the largest file octovox loads (2^26 voxels) and a
/// 1024³ mesh import, well below what a 16 GiB desktop can spare.
pub const DEFAULT_BUDGET_BYTES: u64 = 4 << 30;

static BUDGET_BYTES: AtomicU64 = AtomicU64::new(DEFAULT_BUDGET_BYTES);

/// Sets the budget (the CLI does this once, before any work).
pub fn set_budget_bytes(bytes: u64) {
    BUDGET_BYTES.store(bytes, Ordering::Relaxed);
}

pub fn budget_bytes() -> u64 {
    BUDGET_BYTES.load(Ordering::Relaxed)
}

/// A step whose estimated peak memory is over the budget.
#[derive(Clone, Debug, thiserror::Error, PartialEq, Eq)]
#[error(
    "{what} would need about {} of memory, over the {} budget (--memory-budget raises it)",
    human(*needed),
    human(*budget)
)]
pub struct OverBudget {
    pub what: String,
    pub needed: u64,
    pub budget: u64,
}

/// Refuses `what` when its estimated peak (`bytes`) is over the budget.
pub fn check(what: impl FnOnce() -> String, bytes: u64) -> Result<(), OverBudget> {
    let budget = budget_bytes();
    if bytes > budget { Err(OverBudget { what: what(), needed: bytes, budget }) } else { Ok(()) }
}

/// Bytes as "1.5 GiB", "12.0 MiB" or "512 B".
pub fn human(bytes: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    UNITS
        .iter()
        .find(|(_, size)| bytes >= *size)
        .map_or_else(|| format!("{bytes} B"), |(unit, size)| format!("{:.1} {unit}", bytes as f64 / *size as f64))
}

/// Why a size such as `--memory-budget`'s is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SizeError {
    #[error("'{0}' is not a size such as 4G, 512M or 1000000")]
    NotASize(String),
    #[error("'{text}': unknown unit '{unit}' (use K, M, G or T, as in 4G, 4GB or 4GiB)")]
    Unit { text: String, unit: String },
    #[error("'{0}' is not a usable size")]
    Unusable(String),
}

/// Parses "4G", "512M", "64k", "1000" (bytes; binary units, case-insensitive).
pub fn parse_bytes(text: &str) -> Result<u64, SizeError> {
    let text = text.trim();
    let split = text.find(|c: char| !c.is_ascii_digit()).unwrap_or(text.len());
    let (digits, unit) = text.split_at(split);
    let number: u64 = digits.parse().map_err(|_| SizeError::NotASize(text.to_owned()))?;
    // One unit, spelled K, KB or KiB (any case): `4GiBiBiB` is not one.
    let lower = unit.to_ascii_lowercase();
    let prefix = lower.strip_suffix("ib").or_else(|| lower.strip_suffix('b')).unwrap_or(&lower);
    let shift = match prefix {
        "" if lower.is_empty() || lower == "b" => 0,
        "k" => 10,
        "m" => 20,
        "g" => 30,
        "t" => 40,
        _ => return Err(SizeError::Unit { text: text.to_owned(), unit: unit.to_owned() }),
    };
    number.checked_mul(1 << shift).filter(|b| *b > 0).ok_or_else(|| SizeError::Unusable(text.to_owned()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_print() {
        assert_eq!(parse_bytes("4G"), Ok(4 << 30));
        assert_eq!(parse_bytes("512MiB"), Ok(512 << 20));
        assert_eq!(parse_bytes("1000"), Ok(1000));
        assert!(parse_bytes("0").is_err());
        assert!(parse_bytes("-1G").is_err());
        assert!(parse_bytes("12 parsecs").is_err());
        assert!(parse_bytes("99999999999T").is_err());
        // Issue 24, item 16: a malformed unit was read as its first one.
        for bad in ["4GiBiBiB", "4GBB", "4ibib", "4iB", "4bb", "4KMG"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_bytes("4gb"), Ok(4 << 30));
        assert_eq!(parse_bytes("4kib"), Ok(4 << 10));
        assert_eq!(parse_bytes("100b"), Ok(100));
        assert_eq!(human(3 << 29), "1.5 GiB");
        assert_eq!(human(10), "10 B");
    }
}
