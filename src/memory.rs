//! What a render needs in memory, and what the process may take.
//!
//! The need is estimated before any work, from the scene file and the
//! headers of its assets (no texture is decoded, no mesh parsed): each
//! asset's peak while it loads and what it keeps, the star map, meshes,
//! the film and every copy the outputs make (bloom, the 8-bit image, the
//! EXR's planes, the stereo composites). What is available is the least
//! of the free memory, every cgroup limit above the process (v2, nested as
//! in a Slurm job, and v1) and the address-space limit.

use crate::config::{MaterialConfig, ObjectConfig, SceneConfig};
use std::path::Path;

/// A need in parts, each named for the message that refuses it.
#[derive(Clone, Debug, Default)]
pub struct Need {
    /// What, and how many bytes.
    pub parts: Vec<(String, u64)>,
}

/// MiB, for messages.
pub fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 20) as f64
}

impl Need {
    fn add(&mut self, what: impl Into<String>, bytes: u64) {
        if bytes > 0 {
            self.parts.push((what.into(), bytes));
        }
    }

    /// Everything.
    pub fn total(&self) -> u64 {
        self.parts.iter().map(|p| p.1).sum()
    }

    /// The largest parts, largest first: "film 503 MiB, star map 64 MiB".
    pub fn largest(&self, n: usize) -> String {
        let mut p = self.parts.clone();
        p.sort_by_key(|x| std::cmp::Reverse(x.1));
        p.iter()
            .take(n)
            .map(|(w, b)| format!("{w} {:.0} MiB", mib(*b).ceil()))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Fails, naming the largest parts and the limit, when the need is
    /// more than what is available (nothing is refused where the system
    /// does not tell).
    pub fn check(&self, what: &str) -> Result<(), String> {
        let Some(avail) = available() else {
            return Ok(());
        };
        let need = self.total();
        if need > avail.bytes {
            return Err(format!(
                "{what} needs about {:.0} MiB ({}) but only {:.0} MiB of memory is available ({}): make the largest of these smaller",
                mib(need).ceil(),
                self.largest(4),
                mib(avail.bytes),
                avail.limited_by
            ));
        }
        Ok(())
    }
}

/// The process itself: code, libraries, thread stacks, the colour tables.
const BASE: u64 = 24 << 20;

/// The peak memory of loading a scene's assets and what they keep, from
/// the scene file and the files' headers. Files that cannot be read count
/// as nothing here: loading them reports them.
pub fn assets(cfg: &SceneConfig) -> Need {
    let mut need = Need::default();
    need.add("the program", BASE);
    // Textures load one after another: all are kept, the largest
    // decoding buffer is the transient.
    let mut transient: Vec<(String, u64)> = Vec::new();
    fn texture(key: &str, path: &Path, need: &mut Need, transient: &mut Vec<(String, u64)>) {
        if let Some((keep, decode)) = texture_bytes(path) {
            need.add(key, keep);
            transient.push((format!("decoding {key}"), decode));
        }
    }
    if let Some(d) = &cfg.disk {
        if let Some(t) = &d.texture {
            texture("disk.texture", t, &mut need, &mut transient);
        }
        if let Some(m) = &d.spectrum {
            need.add("disk.spectrum", spectral_set_bytes(m));
        }
    }
    if let Some(t) = &cfg.sky.texture {
        texture("sky.texture", t, &mut need, &mut transient);
    }
    if cfg.sky.stars.is_some() {
        let w = cfg.sky.resolution as u64;
        let texels = w * (w / 2);
        // Luminance and temperature kept, a weighted sum while building,
        // and the Milky Way's coarser grid.
        need.add(
            "the star map (sky.resolution)",
            8 * texels + 4 * texels / 16,
        );
        transient.push(("building the star map".into(), 4 * texels));
    }
    for (i, o) in cfg.objects.iter().enumerate() {
        let material = match o {
            ObjectConfig::Sphere(s) => &s.material,
            ObjectConfig::Rectangle(r) => &r.material,
            ObjectConfig::Mesh(m) => {
                let (tris, verts) = obj_counts(&m.file);
                // The parsed file, the placed mesh and its BVH (and the
                // BVH's build), per triangle and per vertex: measured.
                let bytes = tris * MESH_PER_TRIANGLE + verts * MESH_PER_VERTEX;
                need.add(format!("object.{i}.file ({tris} triangles)"), bytes);
                &m.material
            }
        };
        let (MaterialConfig::Color(s) | MaterialConfig::Mirror(s) | MaterialConfig::Lit(s)) =
            material;
        if let Some(t) = &s.texture {
            texture(
                &format!("object.{i}.material.texture"),
                t,
                &mut need,
                &mut transient,
            );
        }
    }
    if cfg.volume.is_some() {
        // The density grid, 320 x 320 x 33 floats.
        need.add("[volume]", 4 * 320 * 320 * 33);
    }
    // Each cloud's lumpy density, 48^3 floats.
    need.add("[[cloud]]", cfg.clouds.len() as u64 * 4 * 48 * 48 * 48);
    if let Some((what, bytes)) = transient.into_iter().max_by_key(|t| t.1) {
        need.add(what, bytes);
    }
    need
}

/// Peak bytes per triangle and per vertex of a loaded mesh (tobj's arrays,
/// the placed mesh in f64, the BVH and its build), measured on a
/// 10-million-triangle asteroid.
const MESH_PER_TRIANGLE: u64 = 120;
const MESH_PER_VERTEX: u64 = 110;

/// (bytes kept, bytes of the decoded image while it converts) of a
/// texture, from its header.
fn texture_bytes(path: &Path) -> Option<(u64, u64)> {
    use image::ImageDecoder;
    let mut reader = image::ImageReader::open(path)
        .ok()?
        .with_guessed_format()
        .ok()?;
    // The header only: no limit on what the image would need.
    reader.no_limits();
    let decoder = reader.into_decoder().ok()?;
    let (w, h) = decoder.dimensions();
    let texels = w as u64 * h as u64;
    let color = decoder.color_type();
    let decoded = texels * color.bytes_per_pixel() as u64;
    // 8-bit images stay 8-bit RGBA; everything else becomes f32 RGBA.
    let eight = matches!(
        color,
        image::ColorType::L8
            | image::ColorType::La8
            | image::ColorType::Rgb8
            | image::ColorType::Rgba8
    );
    let keep = texels * if eight { 4 } else { 16 };
    // RGBA of the kept kind is used as decoded; others convert.
    let converts = !matches!(color, image::ColorType::Rgba8 | image::ColorType::Rgba32F);
    Some((keep, if converts { decoded } else { 0 }))
}

/// Bytes a spectral set keeps (every wavelength's plane and the alpha as
/// floats), from the manifest and one image's header.
fn spectral_set_bytes(manifest: &Path) -> u64 {
    let Ok(files) = crate::spectral_texture::manifest_files(manifest) else {
        return 0;
    };
    let Some((w, h)) = files.iter().find_map(|f| image::image_dimensions(f).ok()) else {
        return 0;
    };
    // Each plane decoded (16-bit) while the floats are filled.
    (files.len() as u64 * 4 + 2) * w as u64 * h as u64
}

/// (triangles, vertices) of an OBJ file, counted from its lines (a face of
/// k corners is k - 2 triangles).
fn obj_counts(path: &Path) -> (u64, u64) {
    use std::io::BufRead;
    let Ok(f) = std::fs::File::open(path) else {
        return (0, 0);
    };
    let (mut tris, mut verts) = (0u64, 0u64);
    for line in std::io::BufReader::new(f)
        .split(b'\n')
        .map_while(Result::ok)
    {
        match line.get(..2) {
            Some(b"v ") | Some(b"v\t") => verts += 1,
            Some(b"f ") | Some(b"f\t") => {
                let corners = line[2..]
                    .split(|b| b.is_ascii_whitespace())
                    .filter(|w| !w.is_empty())
                    .count() as u64;
                tris += corners.saturating_sub(2);
            }
            _ => {}
        }
    }
    (tris, verts)
}

/// What a render does with its film, for [`film`].
#[derive(Clone, Copy, Debug)]
pub struct Job {
    /// Rows rendered (a tile's, or the whole image's).
    pub rows: u32,
    /// Films held at once: 1; 3 for a stereo render (the mono image and
    /// both eyes); 2 for compare.
    pub films: u32,
    /// The outputs are written (not for a tile).
    pub outputs: bool,
    /// On the GPU backend, whose buffers hold a copy of the assets and of
    /// the film on the host (and on CPU devices such as lavapipe, the
    /// device's memory too).
    pub gpu: bool,
}

impl Job {
    /// `render` of the whole image.
    pub fn render(cfg: &SceneConfig, gpu: bool) -> Job {
        Job {
            rows: cfg.image.height,
            films: if cfg.stereo.is_some() { 3 } else { 1 },
            outputs: true,
            gpu,
        }
    }
}

/// The film's bytes per pixel: XYZ, kept spectra, spectral bloom's bands.
fn film_bytes_per_pixel(cfg: &SceneConfig) -> u64 {
    let sp = &cfg.spectral;
    let n_wl = if sp.enabled { sp.wavelengths as u64 } else { 0 };
    let keep = if sp.enabled && sp.exr_layers {
        4 * n_wl
    } else {
        0
    };
    let bands = if sp.enabled && cfg.bloom.as_ref().is_some_and(|b| b.spectral) {
        12 * crate::film::BANDS as u64
    } else {
        0
    };
    12 + keep + bands
}

/// The film of `job` and the copies its outputs make, added to `need`.
pub fn film(cfg: &SceneConfig, job: Job, mut need: Need) -> Need {
    let img = &cfg.image;
    let px = img.width as u64 * job.rows as u64;
    let film = px * film_bytes_per_pixel(cfg);
    need.add(
        format!("the film ({} x {})", img.width, job.rows),
        film * job.films as u64,
    );
    if job.gpu {
        // The packed scene and the film's read-back.
        let assets: u64 = need.parts.iter().skip(1).map(|p| p.1).sum();
        need.add("the GPU's copy of the scene", 2 * assets);
        need.add("the GPU's film", film);
    }
    if !job.outputs {
        // A tile's channels are copied once to be written.
        need.add("the tile's channels", film);
        return need;
    }
    let mut out = 0;
    if cfg.bloom.is_some() {
        // The bloomed image, and a blur's passes.
        out += 48 * px;
    }
    // The 8-bit image; with a stereo pair the eyes and composites too.
    out += 3 * px + if cfg.stereo.is_some() { 15 * px } else { 0 };
    if img.exr.is_some() {
        let sp = &cfg.spectral;
        let channels = 3
            + if img.exr_xyz { 3 } else { 0 }
            + if sp.enabled && sp.exr_layers {
                sp.wavelengths as u64
            } else {
                0
            };
        let sample = if img.exr_half { 2 } else { 4 };
        // Linear sRGB and the channel planes (compressed and written a
        // block at a time).
        out += 12 * px + channels * sample * px;
    }
    need.add("the outputs (bloom, PNG, EXR)", out);
    need
}

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
