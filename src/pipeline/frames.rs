//! An animation's frames as files: their names, the tags that tie each to
//! its scene and number, and whether one is complete.

use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// The tags (PNG text chunks, EXR comments) of an animation frame: its
/// scene's hash and its number.
pub const FRAME_SCENE: &str = "blackhole:scene";
/// See [`FRAME_SCENE`].
pub const FRAME_NUMBER: &str = "blackhole:frame";

/// `NAME_<k:05>.EXT` beside image.png.
pub fn frame_file(png: &Path, k: u32, ext: &str) -> PathBuf {
    let stem = png
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "frame".into());
    png.with_file_name(format!("{stem}_{k:05}.{ext}"))
}

/// Whether frame `k`'s `files` (its PNG, then its EXR if any) are complete:
/// they exist (they are written atomically, together); one of another size
/// than `size`, or whose PNG or EXR carries another scene's hash than
/// `hash` or another number, is a stale frame, an error (`config` names the
/// scene for the message).
pub fn frame_is_complete(
    files: &[PathBuf],
    k: u32,
    size: (u32, u32),
    hash: &str,
    config: &Path,
) -> Result<bool> {
    if !files.iter().all(|f| f.exists()) {
        return Ok(false);
    }
    if let Ok((w, h)) = image::image_dimensions(&files[0])
        && (w, h) != size
    {
        bail!(
            "{} exists at {w} x {h} and this animation renders {} x {}: remove the stale frames or pass --overwrite",
            files[0].display(),
            size.0,
            size.1
        );
    }
    for f in files {
        let tag = |key| {
            if f.extension().is_some_and(|e| e == "exr") {
                crate::output::exr_tag(f, key).ok().flatten()
            } else {
                crate::output::png_text(f, key).ok().flatten()
            }
        };
        if tag(FRAME_SCENE).as_deref() != Some(hash) || tag(FRAME_NUMBER) != Some(k.to_string()) {
            bail!(
                "{} is not frame {k} of this scene ({} with these settings): it was rendered from another config or by another version; remove the frames, name another image.png, or pass --overwrite to render them again",
                f.display(),
                config.display()
            );
        }
    }
    Ok(true)
}
