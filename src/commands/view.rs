//! `view`: the scene in a window (the viewer's own module does the rest).

use crate::ViewArgs;
use anyhow::{Context, Result, bail};

pub fn view(a: ViewArgs) -> Result<()> {
    let out = match a.out {
        Some(d) => d,
        None => std::env::current_dir().context("cannot read the current directory")?,
    };
    if out.exists() && !out.is_dir() {
        bail!("--out {}: not a folder", out.display());
    }
    let session =
        blackhole::view::Session::open(&a.scene.config, a.scene.overrides(), out.clone())?;
    // Made once the scene is known to be good, as render makes its
    // outputs' folders.
    std::fs::create_dir_all(&out)
        .with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    for w in &session.original.warnings {
        eprintln!("warning: {w}");
    }
    blackhole::view::run(session)
}
