//! The resource guard: a size read from a file or the command line (an image's width and
//! height, a mesh's or a header's count) that would need more memory than this machine has
//! is refused with a clear error *before* anything is allocated, instead of ending in the
//! kernel's out-of-memory killer minutes later. The limit is the machine's or the job's
//! memory, or `RAYLAB_MEMORY_LIMIT`. `raylab --allow-large` turns it off for
//! those who mean it (swap, overcommit, a machine whose memory is not what /proc says).

use std::sync::atomic::{AtomicBool, Ordering};

static ALLOW_LARGE: AtomicBool = AtomicBool::new(false);

/// Turns the guard off (`true`) or on again, for the whole process.
pub fn allow_large(yes: bool) {
    ALLOW_LARGE.store(yes, Ordering::Relaxed);
}

/// The memory this process may use, in bytes: `RAYLAB_MEMORY_LIMIT` when set (bytes, or
/// with a K, M, G or T suffix), else the machine's physical memory (`MemTotal` of
/// /proc/meminfo) or the cgroup's limit (`memory.max`, what a Slurm or Kubernetes job was
/// given), the smaller; `None` where none can be read (then nothing is refused). Totals,
/// not what is free now, so that an input is refused or accepted the same way every run.
pub fn memory_limit() -> Option<u64> {
    if let Ok(v) = std::env::var("RAYLAB_MEMORY_LIMIT") {
        return parse_size(&v);
    }
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|i| parse_mem_total(&i));
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max").ok().and_then(|s| s.trim().parse::<u64>().ok());
    match (total, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// `123`, `64K`, `512M`, `16G`, `1T` (powers of 1024).
fn parse_size(s: &str) -> Option<u64> {
    let s = s.trim();
    let (digits, shift) = match s.char_indices().last()? {
        (i, 'K' | 'k') => (&s[..i], 10),
        (i, 'M' | 'm') => (&s[..i], 20),
        (i, 'G' | 'g') => (&s[..i], 30),
        (i, 'T' | 't') => (&s[..i], 40),
        _ => (s, 0),
    };
    digits.parse::<u64>().ok()?.checked_mul(1 << shift)
}

fn parse_mem_total(info: &str) -> Option<u64> {
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Refuses `bytes` (`None`: the size overflowed) for `what` ("a 100000×100000 film") when
/// it exceeds the machine's memory and the guard is on.
pub fn check(what: &str, bytes: Option<u64>) -> Result<(), String> {
    if ALLOW_LARGE.load(Ordering::Relaxed) {
        return Ok(());
    }
    check_against(what, bytes, memory_limit())
}

fn check_against(what: &str, bytes: Option<u64>, memory: Option<u64>) -> Result<(), String> {
    let Some(memory) = memory else { return Ok(()) };
    match bytes {
        Some(b) if b <= memory => Ok(()),
        Some(b) => Err(format!("{what} would need {} of memory, more than the {} this process may use (pass --allow-large to try anyway)", human(b), human(memory))),
        None => Err(format!("{what} would need more memory than can be counted (its size overflows 64 bits)")),
    }
}

/// Bytes in GiB, MiB or KiB with one decimal, for messages.
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if bytes >= 1 << 30 {
        format!("{:.1} GiB", b / (1u64 << 30) as f64)
    } else if bytes >= 1 << 20 {
        format!("{:.1} MiB", b / (1u64 << 20) as f64)
    } else {
        format!("{:.1} KiB", b / 1024.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_only_what_exceeds_memory() {
        let mem = Some(8u64 << 30);
        assert_eq!(check_against("x", Some(8 << 30), mem), Ok(()));
        assert_eq!(check_against("a 100000×100000 film", Some(160_000_000_000), mem).unwrap_err(), "a 100000×100000 film would need 149.0 GiB of memory, more than the 8.0 GiB this process may use (pass --allow-large to try anyway)");
        assert_eq!(check_against("x", None, mem).unwrap_err(), "x would need more memory than can be counted (its size overflows 64 bits)");
        assert_eq!(check_against("x", None, None), Ok(()));
    }

    #[test]
    fn reads_mem_total_in_kib() {
        assert_eq!(parse_mem_total("MemFree: 1 kB\nMemTotal:       16384 kB\n"), Some(16 << 20));
        assert_eq!(parse_mem_total("nothing"), None);
        assert_eq!((parse_size("512M"), parse_size("16G"), parse_size("123"), parse_size("x")), (Some(512 << 20), Some(16 << 30), Some(123), None));
    }
}
