//! How much memory the process may still take: the least of the machine's
//! free memory, every cgroup limit on the way up from its own (v2 and v1)
//! and its address-space limit.

use std::path::Path;

/// Memory the process may still take, and what limits it.
#[derive(Clone, Debug)]
pub struct Available {
    /// Bytes.
    pub bytes: u64,
    /// The limit that is the least, in words.
    pub limited_by: String,
}

/// What this process may allocate: the least of the free memory, every
/// cgroup limit on the way up from its own (v2 and v1) and its
/// address-space limit. None where the system does not tell.
pub fn available() -> Option<Available> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let free = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))
        .and_then(|v| v.split_whitespace().next()?.parse::<u64>().ok())?
        * 1024;
    let mut best = Available {
        bytes: free,
        limited_by: "the machine's free memory".into(),
    };
    let cgroups = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
    if let Some((bytes, by)) = cgroup_room(&cgroups, Path::new("/sys/fs/cgroup"))
        && bytes < best.bytes
    {
        best = Available {
            bytes,
            limited_by: by,
        };
    }
    if let Some(bytes) = address_space_room()
        && bytes < best.bytes
    {
        best = Available {
            bytes,
            limited_by: "the address-space limit (ulimit -v)".into(),
        };
    }
    Some(best)
}

/// The least room under the memory limits of the cgroups listed in
/// `proc_cgroup` (the text of /proc/self/cgroup) and their ancestors,
/// under the cgroup file systems at `root`: limit less use, with the
/// reclaimable page cache counted as room.
pub fn cgroup_room(proc_cgroup: &str, root: &Path) -> Option<(u64, String)> {
    let read = |p: &Path| std::fs::read_to_string(p).ok();
    let num = |p: &Path| read(p)?.trim().parse::<u64>().ok();
    let stat = |p: &Path, key: &str| {
        read(p)?.lines().find_map(|l| {
            l.strip_prefix(key)?
                .strip_prefix(' ')?
                .trim()
                .parse::<u64>()
                .ok()
        })
    };
    let mut best: Option<(u64, String)> = None;
    let mut consider = |room: u64, dir: &Path| {
        if best.as_ref().is_none_or(|b| room < b.0) {
            best = Some((
                room,
                format!("the memory limit of cgroup {}", dir.display()),
            ));
        }
    };
    for line in proc_cgroup.lines() {
        let mut f = line.splitn(3, ':');
        let (_, controllers, path) = (f.next(), f.next()?, f.next()?);
        let rel = path.trim_start_matches('/');
        let (base, v2) = if controllers.is_empty() {
            (root.to_path_buf(), true)
        } else if controllers.split(',').any(|c| c == "memory") {
            (root.join("memory"), false)
        } else {
            continue;
        };
        // The cgroup and each one above it, up to the root.
        let mut dir = base.join(rel);
        loop {
            if v2 {
                if let (Some(max), Some(cur)) = (
                    num(&dir.join("memory.max")),
                    num(&dir.join("memory.current")),
                ) {
                    let cache = stat(&dir.join("memory.stat"), "inactive_file").unwrap_or(0);
                    consider((max + cache).saturating_sub(cur), &dir);
                }
            } else if let (Some(max), Some(cur)) = (
                num(&dir.join("memory.limit_in_bytes")),
                num(&dir.join("memory.usage_in_bytes")),
            ) {
                // v1 reports "no limit" as a huge number.
                if max < 1 << 60 {
                    let cache = stat(&dir.join("memory.stat"), "total_inactive_file").unwrap_or(0);
                    consider((max + cache).saturating_sub(cur), &dir);
                }
            }
            if dir == base || !dir.pop() || !dir.starts_with(&base) {
                break;
            }
        }
    }
    best
}

/// Room under RLIMIT_AS: the limit less the address space in use.
#[cfg(target_arch = "wasm32")]
fn address_space_room() -> Option<u64> {
    None
}

/// Room under RLIMIT_AS: the limit less the address space in use.
#[cfg(not(target_arch = "wasm32"))]
fn address_space_room() -> Option<u64> {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } != 0
        || lim.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let used = status
        .lines()
        .find_map(|l| l.strip_prefix("VmSize:"))
        .and_then(|v| v.split_whitespace().next()?.parse::<u64>().ok())?
        * 1024;
    Some(lim.rlim_cur.saturating_sub(used))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(p: &Path, text: &str) {
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }

    #[test]
    fn nested_cgroup_v2_limits_are_read_up_the_tree() {
        // A Slurm job's step inside its job inside the user's slice: the
        // job's limit (4 GiB) binds, not the step's (none) or the root's.
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        let job = r.join("system.slice/slurmstepd.scope/job_7");
        let step = job.join("step_0");
        write(&step.join("memory.max"), "max\n");
        write(&step.join("memory.current"), "1000\n");
        write(&job.join("memory.max"), &format!("{}\n", 4u64 << 30));
        write(&job.join("memory.current"), &format!("{}\n", 1u64 << 30));
        write(&job.join("memory.stat"), "anon 1\ninactive_file 1048576\n");
        write(
            &r.join("system.slice/memory.max"),
            &format!("{}\n", 64u64 << 30),
        );
        write(&r.join("system.slice/memory.current"), "0\n");
        let (room, by) =
            cgroup_room("0::/system.slice/slurmstepd.scope/job_7/step_0\n", r).unwrap();
        assert_eq!(room, (3u64 << 30) + (1 << 20));
        assert!(by.ends_with("job_7"), "{by}");
    }

    #[test]
    fn cgroup_v1_memory_limits_are_read() {
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        let g = r.join("memory/docker/abc");
        write(
            &g.join("memory.limit_in_bytes"),
            &format!("{}\n", 2u64 << 30),
        );
        write(
            &g.join("memory.usage_in_bytes"),
            &format!("{}\n", 512u64 << 20),
        );
        write(
            &r.join("memory/memory.limit_in_bytes"),
            "9223372036854771712\n",
        );
        write(&r.join("memory/memory.usage_in_bytes"), "1\n");
        let text = "12:cpu,cpuacct:/docker/abc\n11:memory:/docker/abc\n";
        let (room, _) = cgroup_room(text, r).unwrap();
        assert_eq!(room, (2u64 << 30) - (512 << 20));
        assert!(cgroup_room("11:memory:/none\n", r).is_none());
    }
}
