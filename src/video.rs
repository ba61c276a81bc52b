//! An animation's frames (PNG files) as one video: MP4 through the
//! `ffmpeg` program (H.264, yuv420p), or GIF and animated PNG written
//! in-process. Every video is written to a temporary file beside its target
//! and renamed into place.

use crate::files::Temp;
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

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

/// Checks, before any frame is rendered, that the program that makes
/// `path` is here: MP4 needs ffmpeg (GIF and animated PNG are written
/// in-process). Asked only of a run that will make the video.
pub fn check_encoder(path: &Path) -> Result<()> {
    if Format::of(path) == Some(Format::Mp4) && !ffmpeg_available() {
        bail!(
            "animation.video = {}: an .mp4 is encoded by the ffmpeg program, which is not installed \
             (Debian/Ubuntu: apt-get install ffmpeg); or name a .gif or .png (animated PNG), written without it, \
             or render the frames alone with --no-video",
            path.display()
        );
    }
    Ok(())
}

/// Checks, before any frame is rendered, that `path` can hold frames at
/// `fps`: every container holds the frame delay 1 / fps only within its
/// range (GIF counts hundredths of a second in 16 bits, animated PNG a
/// 16-bit fraction of seconds).
pub fn check(path: &Path, fps: f64) -> Result<()> {
    let delay = 1.0 / fps;
    let refuse = |range: &str| {
        bail!(
            "animation.fps = {fps}: a frame delay of {delay} s, which {} cannot hold ({range}); choose another fps or another kind of video",
            path.display()
        )
    };
    match Format::of(path) {
        Some(Format::Mp4) if !(MP4_FPS.0..=MP4_FPS.1).contains(&fps) => refuse(&format!(
            "an MP4 here runs at {} to {} frames per second",
            MP4_FPS.0, MP4_FPS.1
        )),
        Some(Format::Gif) if !(0.01..=655.35).contains(&delay) => {
            refuse("a GIF's delays are 0.01 to 655.35 s, 100 to 1/655.35 frames per second")
        }
        Some(Format::Apng) if apng_delay(fps).is_none() => {
            refuse("an animated PNG's delays are 1/65535 to 65535 s")
        }
        Some(_) => Ok(()),
        None => bail!(
            "animation.video = {}: expected .mp4, .gif or .png",
            path.display()
        ),
    }
}

/// The frame rates an MP4 is made at: ffmpeg's timing is in whole units of
/// 1/90000 s and players assume rates of at least a frame a few minutes.
const MP4_FPS: (f64, f64) = (1e-3, 1000.0);

/// Encodes `frames` (PNG files of one size, in order) at `fps` into
/// `out`; `quality` is x264's constant rate factor for MP4.
pub fn encode(frames: &[PathBuf], fps: f64, quality: u32, out: &Path) -> Result<()> {
    if frames.is_empty() {
        bail!("no frames to encode into {}", out.display());
    }
    check(out, fps)?;
    check_encoder(out)?;
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
    // ffmpeg reads a list of files: frames need not be numbered from 0.
    let list = Temp::new(&out.with_extension("frames.txt"))?;
    let mut text = String::new();
    let quote = |p: &Path| -> Result<String> {
        Ok(std::path::absolute(p)?
            .display()
            .to_string()
            .replace('\'', "'\\''"))
    };
    for f in frames {
        text += &format!("file '{}'\nduration {}\n", quote(f)?, 1.0 / fps);
    }
    // The concat demuxer ignores the last entry's duration unless the
    // file is listed once more.
    text += &format!("file '{}'\n", quote(&frames[frames.len() - 1])?);
    {
        let mut w = std::io::BufWriter::new(list.file());
        std::io::Write::write_all(&mut w, text.as_bytes())
            .and_then(|_| std::io::Write::flush(&mut w))
            .with_context(|| format!("cannot write the frame list {}", list.path().display()))?;
    }
    let tmp = Temp::new(out)?;
    let mut cmd = Command::new("ffmpeg");
    cmd.args([
        "-y",
        "-nostdin",
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
    // The temporary's name does not say the container.
    .args(["-f", "mp4"])
    .arg(tmp.path())
    .stdin(Stdio::null())
    .stdout(Stdio::null())
    .stderr(Stdio::piped());
    // ffmpeg dies with us, and a signal to us stops it first.
    crate::files::die_with_parent(&mut cmd);
    let child = cmd.spawn().context("cannot run ffmpeg")?;
    let _running = crate::files::Child::register(child.id());
    let output = child.wait_with_output().context("cannot run ffmpeg")?;
    let said = String::from_utf8_lossy(&output.stderr).trim().to_string();
    // ffmpeg can end with status 0 after failing to write (a full disk
    // shows as "Error writing trailer"): its error output and the file
    // itself decide.
    if !output.status.success() || !said.is_empty() {
        // Its own words; the status only where it failed (an "exit
        // status: 0" beside an error reads as a contradiction).
        let how = if output.status.success() {
            String::new()
        } else {
            format!(" ({})", output.status)
        };
        let full = said.contains("No space left") || said.contains("Error writing trailer");
        bail!(
            "ffmpeg failed making {}{how}{}: {}",
            out.display(),
            if full {
                ", the disk is likely full"
            } else {
                ""
            },
            if said.is_empty() { "no message" } else { &said }
        );
    }
    check_mp4(tmp.path()).with_context(|| {
        format!(
            "ffmpeg made an incomplete {} (is the disk full?)",
            out.display()
        )
    })?;
    tmp.sync()?;
    drop(list);
    tmp.persist()
}

/// Checks that an MP4 file is whole: its top-level boxes fill the file
/// exactly and include the header (`ftyp`), the index (`moov`) and the
/// data (`mdat`).
pub fn check_mp4(path: &Path) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path)?;
    let len = f.metadata()?.len();
    let (mut at, mut seen) = (0u64, Vec::new());
    while at < len {
        let mut head = [0u8; 8];
        f.seek(SeekFrom::Start(at))?;
        f.read_exact(&mut head)
            .map_err(|_| anyhow::anyhow!("a box header cut off at byte {at} of {len}"))?;
        let mut size = u32::from_be_bytes(head[..4].try_into().expect("4 bytes")) as u64;
        let kind = String::from_utf8_lossy(&head[4..]).into_owned();
        if size == 1 {
            let mut big = [0u8; 8];
            f.read_exact(&mut big)
                .map_err(|_| anyhow::anyhow!("a box header cut off at byte {at} of {len}"))?;
            size = u64::from_be_bytes(big);
        } else if size == 0 {
            size = len - at;
        }
        if size < 8 || at + size > len {
            bail!("box {kind:?} at byte {at} runs past the end of the file ({len} bytes)");
        }
        seen.push(kind);
        at += size;
    }
    for want in ["ftyp", "moov", "mdat"] {
        if !seen.iter().any(|k| k == want) {
            bail!("no {want} box (boxes: {})", seen.join(", "));
        }
    }
    Ok(())
}

/// The frame delay of an animated PNG at `fps` as the 16-bit fraction of
/// seconds nearest 1 / fps (best rational approximation), if one is within
/// a thousandth of it.
fn apng_delay(fps: f64) -> Option<(u16, u16)> {
    let target = 1.0 / fps;
    if !target.is_finite() || target <= 0.0 {
        return None;
    }
    let mut best: Option<(u16, u16, f64)> = None;
    // Continued-fraction convergents of the delay with 16-bit terms.
    let (mut h0, mut h1, mut k0, mut k1) = (0u64, 1u64, 1u64, 0u64);
    let mut x = target;
    for _ in 0..40 {
        let a = x.floor();
        if a > u16::MAX as f64 {
            break;
        }
        let a = a as u64;
        let (h2, k2) = (a * h1 + h0, a * k1 + k0);
        if h2 > u16::MAX as u64 || k2 > u16::MAX as u64 {
            break;
        }
        if h2 > 0 {
            let err = ((h2 as f64 / k2 as f64) - target).abs() / target;
            best = Some((h2 as u16, k2 as u16, err));
        }
        (h0, h1, k0, k1) = (h1, h2, k1, k2);
        let frac = x - a as f64;
        if frac < 1e-12 {
            break;
        }
        x = 1.0 / frac;
    }
    // Delays below 1/65535 s: 1/65535 is the shortest there is.
    best.filter(|b| b.2 <= 1e-3).map(|b| (b.0, b.1))
}

fn gif(frames: &[PathBuf], fps: f64, out: &Path) -> Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    // GIF delays are whole hundredths of a second: frame k lasts from
    // round(100 k / fps) to round(100 (k + 1) / fps), so the video keeps
    // its rate on average (24 fps: 4, 4, 4, 5, ... hundredths).
    let at = |k: usize| (100.0 * k as f64 / fps).round() as u32;
    crate::output::write_atomic(out, |w| {
        let mut enc = GifEncoder::new_with_speed(w, 10);
        enc.set_repeat(Repeat::Infinite)?;
        for (k, f) in frames.iter().enumerate() {
            let cs = (at(k + 1) - at(k)).max(1);
            let delay = image::Delay::from_numer_denom_ms(10 * cs, 1);
            let rgba = image::DynamicImage::ImageRgb8(load(f)?).to_rgba8();
            enc.encode_frame(image::Frame::from_parts(rgba, 0, 0, delay))?;
        }
        Ok(())
    })
}

fn apng(frames: &[PathBuf], fps: f64, out: &Path) -> Result<()> {
    let first = load(&frames[0])?;
    let (w, h) = first.dimensions();
    let (num, den) = apng_delay(fps)
        .ok_or_else(|| anyhow::anyhow!("{}: no frame delay for {fps} fps", out.display()))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apng_delays_are_the_nearest_fractions() {
        assert_eq!(apng_delay(24.0), Some((1, 24)));
        assert_eq!(apng_delay(1000.0), Some((1, 1000)));
        assert_eq!(apng_delay(29.97), Some((100, 2997)));
        assert_eq!(apng_delay(1.0 / 65535.0), Some((65535, 1)));
        assert_eq!(apng_delay(1e-9), None);
        let (n, d) = apng_delay(1.0 / 7.3).unwrap();
        assert!((n as f64 / d as f64 - 7.3).abs() < 1e-9);
    }

    #[test]
    fn delays_out_of_a_container_are_refused() {
        let named = |f: &str| PathBuf::from(format!("/tmp/v.{f}"));
        assert!(check(&named("gif"), 1000.0).is_err());
        assert!(check(&named("gif"), 1.0 / 700.0).is_err());
        assert!(check(&named("gif"), 100.0).is_ok());
        assert!(check(&named("png"), 1e-9).is_err());
        assert!(check(&named("png"), 1000.0).is_ok());
    }

    #[test]
    fn a_cut_mp4_is_not_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.mp4");
        let boxed = |kind: &[u8; 4], body: usize| {
            let mut b = ((8 + body) as u32).to_be_bytes().to_vec();
            b.extend_from_slice(kind);
            b.extend(std::iter::repeat_n(0u8, body));
            b
        };
        let whole = [boxed(b"ftyp", 16), boxed(b"mdat", 100), boxed(b"moov", 40)].concat();
        std::fs::write(&p, &whole).unwrap();
        check_mp4(&p).unwrap();
        std::fs::write(&p, &whole[..whole.len() - 10]).unwrap();
        assert!(check_mp4(&p).is_err());
        std::fs::write(&p, &whole[..24 + 108]).unwrap();
        assert!(check_mp4(&p).unwrap_err().to_string().contains("moov"));
    }
}
