//! The memory guard: an allocation whose size a user's argument controls is checked against the
//! memory actually available before it is made, so that a huge argument is a typed error
//! instead of an abort (a failed allocation) or the out-of-memory killer.

use crate::Error;

/// Refuses an allocation of `count` items of `size` bytes each, sized by `argument`, when it
/// exceeds the memory available now (Linux: `MemAvailable` in /proc/meminfo; elsewhere only
/// what the address space cannot hold, isize::MAX bytes). The error names the argument and
/// both figures.
pub fn check_allocation(argument: &'static str, count: usize, size: usize) -> Result<(), Error> {
    let bytes = count.checked_mul(size).filter(|&b| b <= isize::MAX as usize);
    // Below this nothing is worth a read of /proc/meminfo (tens of µs, a short run's cost).
    const SMALL: usize = 64 << 20;
    if bytes.is_some_and(|b| b <= SMALL) {
        return Ok(());
    }
    let available = available_bytes();
    match bytes {
        Some(bytes) if available.is_none_or(|a| bytes <= a) => Ok(()),
        _ => {
            let needed = count as f64 * size as f64;
            let available = available.map_or_else(|| "the address space".to_string(), |a| gib(a as f64));
            Err(Error::invalid(
                argument,
                format!("needs {} of memory, more than is available ({available})", gib(needed)),
            ))
        }
    }
}

/// `MemAvailable` of /proc/meminfo in bytes, or None where it cannot be read.
fn available_bytes() -> Option<usize> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: usize = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

fn gib(bytes: f64) -> String {
    format!("{:.3} GiB", bytes / (1u64 << 30) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_allocations_pass_and_huge_ones_name_their_argument() {
        assert!(check_allocation("n", 1000, 8).is_ok());
        let err = check_allocation("links", 1 << 40, 8).unwrap_err().to_string();
        assert!(err.starts_with("links: needs"), "{err}");
        assert!(check_allocation("n", usize::MAX, 8).is_err());
    }
}
