//! An animation's frames (PNG files) as one video: MP4 through the
//! `ffmpeg` program (H.264, yuv420p), or GIF and animated PNG written
//! in-process. Every video is written to a temporary file beside its target
//! and renamed into place.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The container a file name asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// H.264 in MP4, through ffmpeg.
    Mp4,
    /// Animated GIF (256 colours per frame).
    Gif,
    /// Animated PNG (lossless).
    Apng,
}

impl Format {
    /// From the file name's extension.
    pub fn of(path: &Path) -> Option<Format> {
        match path
            .extension()?
            .to_string_lossy()
            .to_ascii_lowercase()
            .as_str()
        {
            "mp4" => Some(Format::Mp4),
            "gif" => Some(Format::Gif),
            "png" => Some(Format::Apng),
            _ => None,
        }
    }
}

/// Whether the `ffmpeg` program runs.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Checks, before any frame is rendered, that `path` can be made: MP4
/// needs the ffmpeg program.
pub fn check(path: &Path) -> Result<()> {
    match Format::of(path) {
        Some(Format::Mp4) if !ffmpeg_available() => bail!(
            "animation.video = {}: an .mp4 is encoded by the ffmpeg program, which is not installed \
             (Debian/Ubuntu: apt-get install ffmpeg); or name a .gif or .png (animated PNG), written without it",
            path.display()
        ),
        Some(_) => Ok(()),
        None => bail!(
            "animation.video = {}: expected .mp4, .gif or .png",
            path.display()
        ),
    }
}

/// Encodes `frames` (PNG files of one size, in order) at `fps` into
/// `out`; `quality` is x264's constant rate factor for MP4.
pub fn encode(frames: &[PathBuf], fps: f64, quality: u32, out: &Path) -> Result<()> {
    if frames.is_empty() {
        bail!("no frames to encode into {}", out.display());
    }
    match Format::of(out) {
        Some(Format::Mp4) => mp4(frames, fps, quality, out),
        Some(Format::Gif) => gif(frames, fps, out),
        Some(Format::Apng) => apng(frames, fps, out),
        None => bail!("{}: expected .mp4, .gif or .png", out.display()),
    }
}

fn load(path: &Path) -> Result<image::RgbImage> {
    Ok(image::open(path)
        .with_context(|| format!("cannot read frame {}", path.display()))?
        .to_rgb8())
}

fn mp4(frames: &[PathBuf], fps: f64, quality: u32, out: &Path) -> Result<()> {
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // ffmpeg reads a list of files: frames need not be numbered from 0.
    let list = tempfile::Builder::new()
        .suffix(".txt")
        .tempfile_in(dir)
        .with_context(|| format!("cannot write in {}", dir.display()))?;
    let mut text = String::new();
    for f in frames {
        let abs = std::path::absolute(f)?;
        text += &format!(
            "file '{}'\nduration {}\n",
            abs.display().to_string().replace('\'', "'\\''"),
            1.0 / fps
        );
    }
    // The concat demuxer ignores the last entry's duration unless the
    // file is listed once more.
    let last = std::path::absolute(&frames[frames.len() - 1])?;
    text += &format!(
        "file '{}'\n",
        last.display().to_string().replace('\'', "'\\''")
    );
    std::fs::write(list.path(), text)?;
    let tmp = tempfile::Builder::new()
        .suffix(".mp4")
        .tempfile_in(dir)
        .with_context(|| format!("cannot write in {}", dir.display()))?;
    let output = Command::new("ffmpeg")
        .args([
            "-y",
            "-loglevel",
            "error",
            "-f",
            "concat",
            "-safe",
            "0",
            "-i",
        ])
        .arg(list.path())
        .args(["-r", &format!("{fps}")])
        .args(["-c:v", "libx264", "-pix_fmt", "yuv420p"])
        .args(["-crf", &quality.to_string()])
        // H.264 in yuv420p needs even sizes.
        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
        .args(["-frames:v", &frames.len().to_string()])
        .arg(tmp.path())
        .output()
        .context("cannot run ffmpeg")?;
    if !output.status.success() {
        bail!(
            "ffmpeg failed making {}: {}",
            out.display(),
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    tmp.persist(out)
        .with_context(|| format!("cannot write {}", out.display()))?;
    Ok(())
}

fn gif(frames: &[PathBuf], fps: f64, out: &Path) -> Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    // GIF delays are in hundredths of a second.
    let delay = image::Delay::from_numer_denom_ms((1000.0 / fps).round().max(10.0) as u32, 1);
    crate::output::write_atomic(out, |w| {
        let mut enc = GifEncoder::new_with_speed(w, 10);
        enc.set_repeat(Repeat::Infinite)?;
        for f in frames {
            let rgba = image::DynamicImage::ImageRgb8(load(f)?).to_rgba8();
            enc.encode_frame(image::Frame::from_parts(rgba, 0, 0, delay))?;
        }
        Ok(())
    })
}

fn apng(frames: &[PathBuf], fps: f64, out: &Path) -> Result<()> {
    let first = load(&frames[0])?;
    let (w, h) = first.dimensions();
    // The frame delay as a fraction: fps given to a thousandth.
    let den = 1000u16;
    let num = (1000.0 / fps).round().clamp(1.0, u16::MAX as f64) as u16;
    crate::output::write_atomic(out, |writer| {
        let mut enc = png::Encoder::new(writer, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_animated(frames.len() as u32, 0)?;
        enc.set_frame_delay(num, den)?;
        let mut png = enc.write_header()?;
        for f in frames {
            let img = load(f)?;
            if img.dimensions() != (w, h) {
                bail!(
                    "frame {} is {} x {}, the first is {w} x {h}",
                    f.display(),
                    img.width(),
                    img.height()
                );
            }
            png.write_image_data(img.as_raw())?;
        }
        png.finish()?;
        Ok(())
    })
}
