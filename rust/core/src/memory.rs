//! The memory guard: an allocation whose size a user's argument controls is checked against the
//! memory actually available to the process before it is made (free memory, its address-space
//! limit and its control group's: [`available_bytes`]), so that a huge argument is a typed
//! error instead of an abort (a failed allocation) or the out-of-memory killer.

use crate::Error;

/// Refuses an allocation of `count` items of `size` bytes each, sized by `argument`, when it
/// exceeds the memory available to this process now ([`available_bytes`]; where nothing can
/// be read, only what the address space cannot hold, isize::MAX bytes). The error names the
/// argument and both figures.
pub fn check_allocation(argument: &'static str, count: usize, size: usize) -> Result<(), Error> {
    check_bytes(count, size).map_err(|reason| Error::invalid(argument, reason))
}

/// As [`check_allocation`], the reason alone (for a caller that names its argument itself).
pub fn check_bytes(count: usize, size: usize) -> Result<(), String> {
    let bytes = count.checked_mul(size).filter(|&b| b <= isize::MAX as usize);
    // Below this nothing is worth a read of /proc (tens of µs, a short run's cost).
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
            Err(format!(
                "needs {} of memory, more than is available ({available})",
                gib(needed)
            ))
        }
    }
}

/// The bytes this process can allocate now on Linux, the least of: the memory available
/// (`MemAvailable` of /proc/meminfo), the address space left under its limit (`ulimit -v`,
/// RLIMIT_AS: /proc/self/limits, less its VmSize), and what its control group has left
/// (cgroup v2's memory.max less memory.current, v1's memory.limit_in_bytes less
/// memory.usage_in_bytes). None where none can be read (another system).
pub fn available_bytes() -> Option<usize> {
    [mem_available(), address_space_left(), cgroup_left()]
        .into_iter()
        .flatten()
        .min()
}

/// The number after `key` on its line of `text`, times `unit`.
fn field(text: &str, key: &str, unit: usize) -> Option<usize> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let value: usize = line[key.len()..].split_whitespace().next()?.parse().ok()?;
    value.checked_mul(unit)
}

fn mem_available() -> Option<usize> {
    field(&std::fs::read_to_string("/proc/meminfo").ok()?, "MemAvailable:", 1024)
}

fn address_space_left() -> Option<usize> {
    // "Max address space   <soft>   <hard>   bytes": the soft limit binds; "unlimited" does not parse.
    let limit = field(
        &std::fs::read_to_string("/proc/self/limits").ok()?,
        "Max address space",
        1,
    )?;
    let mapped = field(&std::fs::read_to_string("/proc/self/status").ok()?, "VmSize:", 1024)?;
    Some(limit.saturating_sub(mapped))
}

fn cgroup_left() -> Option<usize> {
    let read = |path: String| -> Option<usize> { std::fs::read_to_string(path).ok()?.trim().parse().ok() };
    let groups = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    // v2: "0::/path"; v1: "N:memory:/path". Inside a container's namespace the group is the root.
    for (prefix, limit, usage) in [
        ("0::", "memory.max", "memory.current"),
        (
            "memory:",
            "memory/memory.limit_in_bytes",
            "memory/memory.usage_in_bytes",
        ),
    ] {
        let Some(path) = groups.lines().find_map(|l| l.split_once(prefix).map(|(_, p)| p.trim())) else {
            continue;
        };
        for dir in [format!("/sys/fs/cgroup{path}"), "/sys/fs/cgroup".to_string()] {
            let dir = dir.trim_end_matches('/');
            if let (Some(limit), Some(usage)) = (read(format!("{dir}/{limit}")), read(format!("{dir}/{usage}"))) {
                return Some(limit.saturating_sub(usage));
            }
        }
    }
    None
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
