//! Peak memory of this process, as the kernel counts it.

/// The peak resident set size ("high water mark", `VmHWM` in `/proc/self/status`) in bytes, or
/// `None` where the kernel does not report it (outside Linux).
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.trim_start_matches("VmHWM:").trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kib * 1024)
}
