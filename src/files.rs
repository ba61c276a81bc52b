//! The files a command writes, and what keeps them whole.
//!
//! - Every output is first written to a temporary file beside its target,
//!   `.<name>.<pid>@<host>.<random>.tmp`, and a set of outputs (a render's
//!   PNG, EXR and stereo images, a frame's PNG and EXR, a screenshot) is
//!   renamed into place only once all of it is written ([`Batch`]).
//! - SIGINT, SIGTERM and SIGHUP remove the temporaries in flight and stop
//!   the programs this one started (ffmpeg) before the process ends as the
//!   signal asks; a child also dies with us when we are killed outright
//!   ([`die_with_parent`]), and temporaries a killed run left behind are
//!   removed by the next run that writes the same file ([`stale`]).
//! - Before any work, [`Plan::check`] compares every output with every
//!   input file by identity (canonical path, and device and inode), with
//!   the other outputs, and refuses read-only files and names too long.

use anyhow::{Context, Result, bail};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporaries being written and programs running, for the signal handler.
static LIVE: Mutex<Live> = Mutex::new(Live {
    temps: Vec::new(),
    children: Vec::new(),
});

struct Live {
    temps: Vec<PathBuf>,
    children: Vec<u32>,
}

fn live() -> std::sync::MutexGuard<'static, Live> {
    // A panic while holding it leaves the lists usable.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes temporaries and stops children on SIGINT, SIGTERM and SIGHUP,
/// then ends the process as the signal would have. Call once, early.
#[cfg(not(target_arch = "wasm32"))]
pub fn handle_signals() -> Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .context("cannot install the signal handlers")?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(sig) = signals.forever().next() {
                clean_up();
                // Dies of the signal (exit status 128 + sig to a shell).
                let _ = signal_hook::low_level::emulate_default_handler(sig);
                std::process::exit(128 + sig);
            }
        })
        .context("cannot start the signal thread")?;
    Ok(())
}

/// Removes every temporary in flight and stops every child.
#[cfg(not(target_arch = "wasm32"))]
fn clean_up() {
    let l = live();
    for pid in &l.children {
        // SAFETY: kill(2) with a pid we spawned; a stale pid fails harmlessly.
        unsafe {
            libc::kill(*pid as libc::pid_t, libc::SIGTERM);
        }
    }
    for t in &l.temps {
        let _ = std::fs::remove_file(t);
    }
}

/// A child process registered for the signal handler while it runs.
pub struct Child(u32);

impl Child {
    /// Registers `pid`.
    pub fn register(pid: u32) -> Child {
        live().children.push(pid);
        Child(pid)
    }
}

impl Drop for Child {
    fn drop(&mut self) {
        live().children.retain(|p| *p != self.0);
    }
}

/// Makes `cmd`'s process receive SIGKILL when this one dies, however it
/// dies (Linux; elsewhere the signal handler's SIGTERM is what stops it).
pub fn die_with_parent(cmd: &mut std::process::Command) {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::process::CommandExt;
        let parent = std::process::id();
        // SAFETY: prctl and getppid are async-signal-safe, as pre_exec needs.
        unsafe {
            cmd.pre_exec(move || {
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                // The parent may have died before the prctl.
                if libc::getppid() as u32 != parent {
                    return Err(std::io::Error::other("parent gone"));
                }
                Ok(())
            });
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = cmd;
}

/// The system's host name (empty if it has none).
#[cfg(not(target_arch = "wasm32"))]
fn host_name() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer's length is passed; the name is NUL-terminated
    // or fills it.
    if unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) } != 0 {
        return String::new();
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

/// The browser has no host name (nor files to name).
#[cfg(target_arch = "wasm32")]
fn host_name() -> String {
    String::new()
}

/// Whether process `pid` is gone (never, where there are no processes).
fn process_gone(pid: i32) -> bool {
    // SAFETY: signal 0 only asks whether the process exists.
    #[cfg(not(target_arch = "wasm32"))]
    return unsafe { libc::kill(pid, 0) } != 0
        && std::io::Error::last_os_error().raw_os_error() == Some(libc::ESRCH);
    #[cfg(target_arch = "wasm32")]
    {
        let _ = pid;
        false
    }
}

/// This machine's name, for the names of temporaries.
fn host() -> &'static str {
    static HOST: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    HOST.get_or_init(|| {
        let name = host_name();
        // Only what is safe in a file name, and short.
        let clean: String = name
            .chars()
            .filter(|c| c.is_ascii_alphanumeric() || *c == '-')
            .take(32)
            .collect();
        if clean.is_empty() {
            "host".into()
        } else {
            clean
        }
    })
}

/// Longest file name most file systems take (bytes).
pub const MAX_NAME: usize = 255;

/// The prefix of the temporaries of `target`: `.<name>.<pid>@<host>.`,
/// the name shortened (at a character boundary) so that the whole
/// temporary name stays within [`MAX_NAME`].
fn temp_prefix(target: &Path) -> String {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tail = format!(".{}@{}.", std::process::id(), host());
    // '.', the random part (6) and ".tmp".
    let room = MAX_NAME - 1 - tail.len() - 6 - 4;
    let mut cut = name.len().min(room);
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!(".{}{tail}", &name[..cut])
}

/// Removes the temporaries of `target` that a killed run on this machine
/// left behind (their process is gone); others' are left alone.
pub fn stale(target: &Path) {
    let dir = folder(target);
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = file.strip_suffix(".tmp") else {
            continue;
        };
        // .<name>.<pid>@<host>.<random>, the name possibly shortened.
        let Some(rest) = rest.strip_prefix('.') else {
            continue;
        };
        let Some((before, _random)) = rest.rsplit_once('.') else {
            continue;
        };
        let Some((stem, owner)) = before.rsplit_once('.') else {
            continue;
        };
        let Some((pid, h)) = owner.split_once('@') else {
            continue;
        };
        if h != host() || stem.is_empty() || !name.starts_with(stem) {
            continue;
        }
        let Ok(pid) = pid.parse::<i32>() else {
            continue;
        };
        if pid as u32 == std::process::id() {
            continue;
        }
        if process_gone(pid) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// The folder a file goes in ("." for a bare name).
pub fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A temporary file beside its target, registered for the signal handler
/// and removed when dropped unless renamed into place.
pub struct Temp {
    file: Option<tempfile::NamedTempFile>,
    path: PathBuf,
    target: PathBuf,
    /// In the signal handler's list.
    listed: bool,
}

impl Temp {
    /// Creates the temporary for `target` (mode 0644 less the umask), its
    /// folder first if needed.
    pub fn new(target: &Path) -> Result<Temp> {
        let dir = folder(target);
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create folder {}", dir.display()))?;
        stale(target);
        let mut builder = tempfile::Builder::new();
        let prefix = temp_prefix(target);
        builder.prefix(&prefix).suffix(".tmp").rand_bytes(6);
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
        // Registered before it exists, so a signal cannot slip between.
        let mut l = live();
        let file = builder
            .tempfile_in(dir)
            .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
        let path = file.path().to_path_buf();
        l.temps.push(path.clone());
        drop(l);
        Ok(Temp {
            file: Some(file),
            path,
            target: target.to_path_buf(),
            listed: true,
        })
    }

    /// The temporary's path (for programs that write it themselves).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file, to write.
    pub fn file(&self) -> &std::fs::File {
        self.file.as_ref().expect("not yet renamed").as_file()
    }

    /// Flushes it to the disk (a full disk shows here at the latest).
    pub fn sync(&self) -> Result<()> {
        self.file()
            .sync_all()
            .with_context(|| format!("cannot write {}", self.target.display()))
    }

    /// Renames it over its target.
    pub fn persist(mut self) -> Result<()> {
        let file = self.file.take().expect("not yet renamed");
        file.persist(&self.target)
            .map_err(|e| e.error)
            .with_context(|| format!("cannot replace {}", self.target.display()))?;
        Ok(())
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        // Dropping the NamedTempFile (if still held) removes the file.
        self.file = None;
        if self.listed {
            live().temps.retain(|p| *p != self.path);
        }
    }
}

/// Files written together: each is complete in its temporary before any
/// replaces its target, so a failure (a full disk, an error, a signal)
/// leaves the old files or none, never half a set.
#[derive(Default)]
pub struct Batch {
    staged: Vec<Temp>,
}

impl Batch {
    /// An empty set.
    pub fn new() -> Batch {
        Batch::default()
    }

    /// Writes `path`'s content to its temporary through `write`.
    pub fn write(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut BufWriter<&std::fs::File>) -> Result<()>,
    ) -> Result<()> {
        let tmp = Temp::new(path)?;
        {
            let mut w = BufWriter::new(tmp.file());
            write(&mut w).with_context(|| format!("cannot write {}", path.display()))?;
            w.flush()
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        tmp.sync()?;
        self.staged.push(tmp);
        Ok(())
    }

    /// Adds a temporary written by other means.
    pub fn add(&mut self, tmp: Temp) {
        self.staged.push(tmp);
    }

    /// Renames every file into place. A signal waits until the whole set
    /// is in place (the handler takes the same lock), so it finds either
    /// all the temporaries or none.
    pub fn commit(mut self) -> Result<()> {
        let mut l = live();
        let mut failure = None;
        for t in &mut self.staged {
            let file = t.file.take().expect("not yet renamed");
            match file.persist(&t.target) {
                Ok(_) => {
                    l.temps.retain(|p| *p != t.path);
                    t.listed = false;
                }
                Err(e) => {
                    t.file = Some(e.file);
                    failure = Some(
                        anyhow::Error::new(e.error)
                            .context(format!("cannot replace {}", t.target.display())),
                    );
                    break;
                }
            }
        }
        // Released before the rest (if any) is dropped, which takes it.
        drop(l);
        failure.map_or(Ok(()), Err)
    }
}

/// The inputs and outputs of a command, checked against each other before
/// any work.
#[derive(Default)]
pub struct Plan {
    /// What each input is (its key) and where.
    pub inputs: Vec<(String, PathBuf)>,
    /// What each output is and where.
    pub outputs: Vec<(String, PathBuf)>,
}

/// Canonical folders, looked up once each (an animation's frames share one).
#[derive(Default)]
struct Folders(std::collections::HashMap<PathBuf, Option<PathBuf>>);

impl Folders {
    /// The canonical path a file would have: its folder's canonical path
    /// and its name (an output that does not exist yet, or is a link,
    /// which renaming replaces, is named by where it goes).
    fn place(&mut self, path: &Path) -> PathBuf {
        let dir = folder(path).to_path_buf();
        let canon = self
            .0
            .entry(dir.clone())
            .or_insert_with(|| std::fs::canonicalize(&dir).ok());
        match (canon, path.file_name()) {
            (Some(d), Some(n)) => d.join(n),
            _ => std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
        }
    }
}

/// Device and inode of an existing file.
fn inode(path: &Path) -> Option<(u64, u64)> {
    let m = std::fs::metadata(path).ok()?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some((m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = m;
        None
    }
}

impl Plan {
    /// An empty plan.
    pub fn new() -> Plan {
        Plan::default()
    }

    /// Adds an input.
    pub fn input(&mut self, what: impl Into<String>, path: impl Into<PathBuf>) {
        self.inputs.push((what.into(), path.into()));
    }

    /// Adds an output.
    pub fn output(&mut self, what: impl Into<String>, path: impl Into<PathBuf>) {
        self.outputs.push((what.into(), path.into()));
    }

    /// Refuses, naming the files: an output that is one of the inputs (the
    /// same file by canonical path or by device and inode), two outputs
    /// that are one file, an output that exists read-only, a file name
    /// longer than [`MAX_NAME`] bytes, and a folder that cannot be written.
    pub fn check(&self) -> Result<()> {
        use std::collections::HashMap;
        // An empty name would be read as the current folder.
        if let Some((what, _)) = self
            .inputs
            .iter()
            .chain(&self.outputs)
            .find(|(_, p)| p.as_os_str().is_empty())
        {
            bail!("{what} = \"\": an empty path; expected a file name");
        }
        let mut folders = Folders::default();
        // Inputs by place and by inode; a link is also the file it names.
        let mut by_place: HashMap<PathBuf, usize> = HashMap::new();
        let mut by_inode: HashMap<(u64, u64), usize> = HashMap::new();
        for (i, (_, p)) in self.inputs.iter().enumerate() {
            by_place.entry(folders.place(p)).or_insert(i);
            if let Ok(target) = std::fs::canonicalize(p) {
                by_place.entry(target).or_insert(i);
            }
            if let Some(n) = inode(p) {
                by_inode.entry(n).or_insert(i);
            }
        }
        let mut out_place: HashMap<PathBuf, usize> = HashMap::new();
        let mut out_inode: HashMap<(u64, u64), usize> = HashMap::new();
        let mut probed: std::collections::HashSet<PathBuf> = Default::default();
        for (o, (what, out)) in self.outputs.iter().enumerate() {
            let name_len = out.file_name().map_or(0, |n| n.len());
            if name_len > MAX_NAME {
                bail!(
                    "{what} = {}: the file name is {name_len} bytes, more than the {MAX_NAME} a file system takes",
                    out.display()
                );
            }
            if out.is_dir() {
                bail!("cannot write {what} = {}: it is a folder", out.display());
            }
            let place = folders.place(out);
            let node = inode(out);
            let input = by_place
                .get(&place)
                .or_else(|| node.and_then(|n| by_inode.get(&n)));
            if let Some(&i) = input {
                let (key, path) = &self.inputs[i];
                bail!(
                    "{what} = {} is the input {key} = {}: writing it would destroy the input; name another output",
                    out.display(),
                    path.display()
                );
            }
            let twin = out_place
                .get(&place)
                .or_else(|| node.and_then(|n| out_inode.get(&n)));
            if let Some(&j) = twin {
                let (other, path) = &self.outputs[j];
                bail!(
                    "{what} = {} and {other} = {} are the same file: one would replace the other; name them apart",
                    out.display(),
                    path.display()
                );
            }
            if let Ok(m) = std::fs::metadata(out)
                && m.permissions().readonly()
            {
                bail!(
                    "{what} = {} exists and is read-only: make it writable (chmod u+w) to replace it, or name another output",
                    out.display()
                );
            }
            if probed.insert(folder(out).to_path_buf()) {
                check_writable(out)?;
            }
            out_place.insert(place, o);
            if let Some(n) = node {
                out_inode.insert(n, o);
            }
        }
        Ok(())
    }
}

/// Every file a scene reads, with its key: textures, the spectral set's
/// manifest and the images it names, the star catalogue, meshes. (A
/// manifest that cannot be read adds only itself: building the scene
/// reports it.)
pub fn scene_inputs(cfg: &crate::config::SceneConfig) -> Vec<(String, PathBuf)> {
    let mut c = cfg.clone();
    let mut out = Vec::new();
    for (key, p) in c.paths_mut() {
        if matches!(key.as_str(), "image.png" | "image.exr" | "animation.video") {
            continue;
        }
        if key == "disk.spectrum" {
            for f in crate::spectral_texture::manifest_files(p).unwrap_or_default() {
                out.push((format!("{key} (an image of the set)"), f));
            }
        }
        out.push((key, p.clone()));
    }
    out
}

/// Checks that `path` can be written: its folder exists or can be made,
/// and a file can be created in it (then removed).
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = folder(path);
    std::fs::create_dir_all(dir).with_context(|| {
        format!(
            "cannot create folder {} for {}",
            dir.display(),
            path.display()
        )
    })?;
    tempfile::Builder::new()
        .prefix(".blackhole-probe.")
        .tempfile_in(dir)
        .with_context(|| {
            format!(
                "cannot write {}: folder {} is not writable",
                path.display(),
                dir.display()
            )
        })?;
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_batch_leaves_neither_file() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.exr"));
        std::fs::write(&a, "old").unwrap();
        let mut batch = Batch::new();
        batch.write(&a, |w| Ok(w.write_all(b"new")?)).unwrap();
        let r = batch.write(&b, |w| {
            w.write_all(b"partial")?;
            bail!("disk full")
        });
        assert!(r.is_err());
        drop(batch);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert!(!b.exists());
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "temporaries removed: {names:?}");
    }

    #[test]
    fn a_committed_batch_replaces_every_file() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.exr"));
        let mut batch = Batch::new();
        batch.write(&a, |w| Ok(w.write_all(b"A")?)).unwrap();
        batch.write(&b, |w| Ok(w.write_all(b"B")?)).unwrap();
        assert!(
            !a.exists() && !b.exists(),
            "nothing in place before the commit"
        );
        batch.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "A");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "B");
        #[cfg(unix)]
        {
            // 0644 less the umask, as for any file made with 0666.
            use std::os::unix::fs::PermissionsExt;
            let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
            let plain = dir.path().join("plain");
            std::fs::write(&plain, "").unwrap();
            assert_eq!(mode(&a), mode(&plain) & 0o644);
        }
    }

    #[test]
    fn long_names_get_short_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let name = format!("{}.png", "x".repeat(MAX_NAME - 4));
        let target = dir.path().join(&name);
        let t = Temp::new(&target).unwrap();
        let tmp = t.path().file_name().unwrap().len();
        assert!(tmp <= MAX_NAME, "{tmp}");
        t.persist().unwrap();
        assert!(target.exists());
    }

    #[test]
    fn stale_temporaries_of_dead_processes_go() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.png");
        // A process that has exited: its pid is free (until reused).
        let dead = std::process::Command::new("true").spawn().unwrap();
        let pid = dead.id();
        let mut dead = dead;
        dead.wait().unwrap();
        let left = dir
            .path()
            .join(format!(".out.png.{pid}@{}.abcdef.tmp", host()));
        let other_host = dir
            .path()
            .join(format!(".out.png.{pid}@elsewhere.abcdef.tmp"));
        let alive = dir.path().join(format!(
            ".out.png.{}@{}.abcdef.tmp",
            std::process::id(),
            host()
        ));
        let unrelated = dir
            .path()
            .join(format!(".other.png.{pid}@{}.abcdef.tmp", host()));
        for f in [&left, &other_host, &alive, &unrelated] {
            std::fs::write(f, "x").unwrap();
        }
        stale(&target);
        assert!(!left.exists());
        assert!(other_host.exists() && alive.exists() && unrelated.exists());
    }

    #[test]
    fn outputs_that_are_inputs_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("sky.png");
        std::fs::write(&input, "x").unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let check = |out: PathBuf| {
            let mut p = Plan::new();
            p.input("sky.texture", &input);
            p.output("image.png", out);
            p.check()
        };
        // Through `..`, through a linked folder, as a hard link.
        assert!(check(sub.join("../sky.png")).is_err());
        #[cfg(unix)]
        {
            let link = dir.path().join("link");
            std::os::unix::fs::symlink(dir.path(), &link).unwrap();
            let e = check(link.join("sky.png")).unwrap_err().to_string();
            assert!(e.contains("sky.texture"), "{e}");
            let hard = dir.path().join("hard.png");
            std::fs::hard_link(&input, &hard).unwrap();
            assert!(check(hard).is_err());
        }
        assert!(check(dir.path().join("out.png")).is_ok());
    }
}
