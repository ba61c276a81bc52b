//! A private runtime folder for Mesa's Vulkan drivers.
//!
//! Mesa's device-select layer asks Wayland for the default device while
//! adapters are listed, and libwayland prints `error: XDG_RUNTIME_DIR is
//! invalid or not set` when that folder is missing (servers, containers,
//! CI), although the render succeeds. Every native entry point that opens
//! the GPU (the CLI, the library, Python, the tests) comes through here
//! first, so no run prints it.

use std::path::Path;
use std::sync::Once;

/// Points `XDG_RUNTIME_DIR` at a folder of ours (mode 0700 under the
/// system's temporary folder) when it is unset or not ours; once per
/// process.
pub fn ensure_runtime_dir() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        if let Some(dir) = needed() {
            // SAFETY: Rust readers of the environment take the same lock
            // as this write. The CLI and Python's import call this before
            // any thread of ours starts; a library user's first GPU open
            // calls it before Vulkan (the environment's C reader here) is
            // loaded, while other threads of ours only render.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir) };
        }
    });
}

/// The folder to use, or None when the current one is fine (or none of
/// ours can be made).
fn needed() -> Option<std::path::PathBuf> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    // SAFETY: getuid cannot fail.
    let uid = unsafe { libc::getuid() };
    let ours = |p: &Path| {
        std::fs::metadata(p).is_ok_and(|m| m.is_dir() && m.uid() == uid && m.mode() & 0o077 == 0)
    };
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| ours(Path::new(&d))) {
        return None;
    }
    let dir = std::env::temp_dir().join(format!("blackhole-runtime-{uid}"));
    if std::fs::create_dir(&dir).is_ok() {
        let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
    }
    ours(&dir).then_some(dir)
}
