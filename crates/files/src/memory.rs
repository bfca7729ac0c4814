//! How much memory this process may still take, before a run takes it: the least of the
//! machine's available memory (`MemAvailable`), the process's address-space and data limits
//! (`ulimit -v`, `ulimit -d`, less what the process already maps) and its memory cgroup's
//! limit less its usage (v2 `memory.max`, v1 `memory.limit_in_bytes`, at every level of the
//! hierarchy). A run past any of them would be killed or aborted at an allocation; within the
//! least, it stops with a typed error before it allocates.

use std::path::{Path, PathBuf};

/// Address space that one heap of glibc's malloc (an arena of a thread) reserves beyond what
/// it uses.
const ARENA: u64 = 64 << 20;

/// The address space the threads' heaps may reserve: glibc makes up to `MALLOC_ARENA_MAX`
/// arenas (8 per core where it is not set) of [`ARENA`] each, whatever the run needs (measured:
/// 1.7 GB of address space for a run of 57 MB on 2 cores).
fn thread_heaps() -> u64 {
    let arenas = std::env::var("MALLOC_ARENA_MAX")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .unwrap_or_else(|| 8 * std::thread::available_parallelism().map_or(1, |n| n.get() as u64));
    arenas * ARENA
}

/// The threads that multiply dense matrices in a run: the calling thread and rayon's pool
/// (one per core).
fn threads() -> u64 {
    1 + std::thread::available_parallelism().map_or(1, |n| n.get() as u64)
}

/// The bytes of the last-level (L3) cache, 0 where unknown.
fn l3_bytes() -> u64 {
    let dirs = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache")
        .into_iter()
        .flatten()
        .flatten();
    dirs.filter(|d| std::fs::read_to_string(d.path().join("level")).is_ok_and(|l| l.trim() == "3"))
        .filter_map(|d| std::fs::read_to_string(d.path().join("size")).ok())
        .filter_map(|size| {
            let t = size.trim();
            let (digits, unit) = t.split_at(t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len()));
            let n: u64 = digits.parse().ok()?;
            Some(match unit {
                "K" => n << 10,
                "M" => n << 20,
                "G" => n << 30,
                _ => n,
            })
        })
        .max()
        .unwrap_or(0)
}

/// The scratch of faer's dense products (private-gemm): twice the L3 cache per thread,
/// allocated whole by a thread's first large product and touched only as used (960 MiB a
/// thread with a 480 MiB L3, measured: the allocation that aborted a run under `ulimit -d`).
fn dense_scratch() -> u64 {
    threads() * 2 * l3_bytes()
}

/// Address space the solver's threads reserve whatever the run needs: the dense products'
/// scratch ([`dense_scratch`]) and glibc's heaps (arenas).
fn thread_reserve() -> u64 {
    dense_scratch() + thread_heaps()
}

/// Under an address-space limit (`ulimit -v`), the program runs again with `MALLOC_ARENA_MAX=2`
/// (glibc's own setting, read when a process starts), so that its threads' heaps reserve
/// 128 MiB of the limit, not 64 MiB per thread up to 8 per core: the memory estimate then
/// holds, and a run too large is refused by it instead of aborting at an allocation. Does
/// nothing without a limit, with the variable set, or off Linux.
pub fn bound_heaps_under_an_address_space_limit() {
    #[cfg(target_os = "linux")]
    if rlimit("Max address space").is_some() && std::env::var_os("MALLOC_ARENA_MAX").is_none() {
        use std::os::unix::process::CommandExt;
        if let Ok(exe) = std::env::current_exe() {
            // exec returns only where it failed: the run goes on as it is
            let _ = std::process::Command::new(exe)
                .args(std::env::args_os().skip(1))
                .env("MALLOC_ARENA_MAX", "2")
                .exec();
        }
    }
}

/// The memory left, and which limit leaves the least.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Available {
    /// Bytes.
    pub bytes: u64,
    /// The limit that leaves the least, in words.
    pub limit: &'static str,
}

/// Bytes of peak resident memory of this process (VmHWM), 0 where unknown.
pub fn peak_bytes() -> u64 {
    status_kib("VmHWM:").map_or(0, |kb| kb * 1024)
}

/// The memory this process may still take, `None` where nothing is known (not Linux).
pub fn available() -> Option<Available> {
    available_to_one_of(1)
}

/// The memory this process may still take as one of `processes` alike (the ranks of an MPI
/// run on one machine): the machine's available memory and the cgroup's shared among them,
/// the process's own limits (`ulimit -v`, `ulimit -d`) its own; `None` where nothing is known.
pub fn available_to_one_of(processes: u64) -> Option<Available> {
    let mut candidates: Vec<Available> = vec![];
    let mut add = |bytes: Option<u64>, limit: &'static str| {
        if let Some(bytes) = bytes {
            candidates.push(Available { bytes, limit });
        }
    };
    let share = |bytes: u64| bytes / processes.max(1);
    add(
        meminfo_kib("MemAvailable:").map(|kb| share(kb * 1024)),
        "the machine's available memory",
    );
    // the address space counts what is mapped (thread stacks and malloc's arenas too), the
    // data limit what the heap holds
    // (and the threads a run starts reserve address space of their own)
    add(
        rlimit("Max address space")
            .map(|l| l.saturating_sub(status_kib("VmSize:").unwrap_or(0) * 1024 + thread_reserve())),
        "the address-space limit (ulimit -v), less what the solver's threads reserve of it",
    );
    // (the dense products' scratch, allocated whole by each thread's first large product,
    // counts in the data limit too: an allocation past it aborts the process)
    add(
        rlimit("Max data size").map(|l| l.saturating_sub(status_kib("VmData:").unwrap_or(0) * 1024 + dense_scratch())),
        "the data-size limit (ulimit -d), less the dense products' scratch of the solver's threads",
    );
    add(cgroup_left().map(share), "the memory cgroup's limit");
    candidates.into_iter().min_by_key(|a| a.bytes)
}

/// A value in KiB of /proc/self/status.
fn status_kib(key: &str) -> Option<u64> {
    kib_of(&std::fs::read_to_string("/proc/self/status").ok()?, key)
}

/// A value in KiB of /proc/meminfo.
fn meminfo_kib(key: &str) -> Option<u64> {
    kib_of(&std::fs::read_to_string("/proc/meminfo").ok()?, key)
}

fn kib_of(text: &str, key: &str) -> Option<u64> {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|l| l.split_whitespace().next()?.parse().ok())
}

/// The soft limit of `/proc/self/limits`'s line `name` in bytes, `None` where unlimited.
fn rlimit(name: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = text.lines().find(|l| l.starts_with(name))?;
    line[name.len()..].split_whitespace().next()?.parse().ok()
}

/// A cgroup file's number, `None` for `max` or an unreadable file.
fn number(path: &Path) -> Option<u64> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// The least of `limit - usage` over the memory cgroup of this process and its ancestors.
fn cgroup_left() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    cgroup_left_in(&text, Path::new("/sys/fs/cgroup"))
}

/// As [`cgroup_left`], for the `/proc/self/cgroup` text `text` and the hierarchies mounted
/// under `mount` (v2 at `mount`, v1's memory controller at `mount/memory`).
fn cgroup_left_in(text: &str, mount: &Path) -> Option<u64> {
    let mut least: Option<u64> = None;
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(_), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        let (root, limit, usage) = match controllers {
            // v2: the unified hierarchy
            "" => (mount.to_path_buf(), "memory.max", "memory.current"),
            c if c.split(',').any(|c| c == "memory") => {
                (mount.join("memory"), "memory.limit_in_bytes", "memory.usage_in_bytes")
            }
            _ => continue,
        };
        // the process's own group and every group above it (each may limit it); in a
        // container the path may not exist under the mount, whose root is then the group
        let mut dir: PathBuf = root.join(path.trim_start_matches('/'));
        loop {
            if let (Some(l), Some(u)) = (number(&dir.join(limit)), number(&dir.join(usage))) {
                // v1 writes an unlimited group as a huge number
                if l < 1 << 60 {
                    let left = l.saturating_sub(u);
                    least = Some(least.map_or(left, |x| x.min(left)));
                }
            }
            if dir == root || !dir.pop() || !dir.starts_with(&root) {
                break;
            }
        }
    }
    least
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_limit_is_found_and_named() {
        // the memory of a shared machine moves between two reads: the bound is the larger of
        // the reads before and after, with a slack for what moved within them
        let before = meminfo_kib("MemAvailable:").unwrap() * 1024;
        let a = available().expect("Linux knows its memory");
        let after = meminfo_kib("MemAvailable:").unwrap() * 1024;
        assert!(a.bytes > 0);
        assert!(
            a.bytes <= before.max(after) + (1 << 30),
            "{} > {before}, {after}",
            a.bytes
        );
        assert!(!a.limit.is_empty());
        assert!(peak_bytes() > 0);
        assert_eq!(kib_of("VmSize:\t  1234 kB\n", "VmSize:"), Some(1234));
    }

    /// A v2 group under a limited parent, and a v1 memory group: the least room of all.
    #[test]
    fn cgroup_limits_are_read_at_every_level() {
        let mount = tempfile::tempdir().unwrap();
        let write = |dir: &Path, files: &[(&str, &str)]| {
            std::fs::create_dir_all(dir).unwrap();
            for (f, v) in files {
                std::fs::write(dir.join(f), v).unwrap();
            }
        };
        let m = mount.path();
        write(&m.join("a"), &[("memory.max", "3000\n"), ("memory.current", "1000\n")]);
        write(&m.join("a/b"), &[("memory.max", "max\n"), ("memory.current", "900\n")]);
        assert_eq!(cgroup_left_in("0::/a/b\n", m), Some(2000));
        write(
            &m.join("memory/job"),
            &[("memory.limit_in_bytes", "1500"), ("memory.usage_in_bytes", "700")],
        );
        assert_eq!(cgroup_left_in("0::/a/b\n4:memory:/job\n", m), Some(800));
        // v1's "unlimited", and a group the mount does not show
        write(
            &m.join("memory"),
            &[
                ("memory.limit_in_bytes", "9223372036854771712"),
                ("memory.usage_in_bytes", "5"),
            ],
        );
        assert_eq!(cgroup_left_in("4:memory:/elsewhere\n", m), None);
    }
}
