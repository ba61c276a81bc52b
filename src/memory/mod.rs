//! What a render needs in memory, and what the process may take.
//!
//! The need is estimated before any work, from the scene file and the
//! headers of its assets (no texture is decoded, no mesh parsed): each
//! asset's peak while it loads and what it keeps, the star map, meshes,
//! the film and every copy the outputs make (bloom, the 8-bit image, the
//! EXR's planes, the stereo composites). What is available is the least
//! of the free memory, every cgroup limit above the process (v2, nested as
//! in a Slurm job, and v1) and the address-space limit.

pub mod room;

pub use room::{Available, available, cgroup_room};

use crate::config::{Filter, MaterialConfig, ObjectConfig, SceneConfig};
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
    // The footprint filter reads mip levels: a third more.
    let levels = |f: Filter, bytes: u64| match f {
        Filter::Footprint => bytes + bytes / 3,
        _ => bytes,
    };
    let texture =
        |key: &str, path: &Path, filter: Filter, need: &mut Need, transient: &mut Vec<_>| {
            if let Some((keep, decode)) = texture_bytes(path) {
                need.add(key, levels(filter, keep));
                transient.push((format!("decoding {key}"), decode));
            }
        };
    if let Some(d) = &cfg.disk {
        if let Some(t) = &d.texture {
            texture("disk.texture", t, d.filter, &mut need, &mut transient);
        }
        if let Some(m) = &d.spectrum {
            need.add("disk.spectrum", levels(d.filter, spectral_set_bytes(m)));
        }
    }
    if let Some(t) = &cfg.sky.texture {
        texture("sky.texture", t, cfg.sky.filter, &mut need, &mut transient);
    }
    if let Some(crate::config::MediumConfig::Grmhd(g)) = &cfg.medium {
        // A snapshot's primitives (8 doubles a cell, about its file) are
        // read a few radial rows at a time (grmhd::dump::Dump::rows: two
        // copies of four rows, an eighth of the file where it has 64 rows
        // or more; a torus built in memory is held whole while its cells
        // are made), ten single-precision values a cell kept, and the
        // dark and smooth parts' running counts (grmhd::dark).
        let (prims, held) = match (&g.dump, &g.torus) {
            (Some(p), _) => {
                let file = std::fs::metadata(p).map_or(0, |m| m.len());
                (file, file / 8)
            }
            (None, Some(t)) => {
                let n = crate::transfer::grmhd::torus::TorusOptions::parse(
                    &t.metric, &t.grid, t.funnel,
                )
                .map_or(0, |o| o.n.iter().product::<usize>() as u64 * 64);
                (n, n)
            }
            _ => (0, 0),
        };
        need.add(
            "medium.dump (the simulation's cells)",
            prims / 64 * (40 + crate::transfer::grmhd::dark::Darkness::BYTES_PER_CELL as u64),
        );
        transient.push(("reading medium.dump".into(), held));
    }
    if let Some(path) = &cfg.sky.stars
        && cfg.sky.filter == Filter::Footprint
    {
        // Point stars: the index keeps about 24 bytes a star, a catalogue
        // row takes about 40; parsing holds the text, the rows and the
        // stars at once (measured: 151 MiB at the peak for a 99 MB
        // catalogue of 2.5 million stars). The map keeps the Milky Way.
        let file = std::fs::metadata(path).map_or(0, |m| m.len());
        need.add("sky.stars (point stars)", file * 3 / 5);
        let w = cfg.sky.resolution as u64;
        need.add(
            "the Milky Way (sky.resolution)",
            levels(Filter::Footprint, w * w / 32),
        );
        transient.push(("parsing sky.stars".into(), file * 8 / 5));
    } else if cfg.sky.stars.is_some() {
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
            // The footprint filter adds the mip levels.
            texture(
                &format!("object.{i}.material.texture"),
                t,
                s.filter,
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

/// What `relens` needs of the lens map `exr` and the `panorama`, from
/// their headers, before either is read: the panorama's texels (and their
/// mip levels, which the footprint filter reads) and its decoding buffer,
/// every channel of the EXR as it is read and the map kept from it, the
/// filtered pixels and the output's encoding (`exr_out`: float RGBA,
/// else 8-bit RGB). Files that cannot be read count as nothing here:
/// reading them reports them.
pub fn relens(exr: &Path, panorama: &Path, exr_out: bool) -> Need {
    let mut need = Need::default();
    need.add("the program", BASE);
    if let Some((keep, decode)) = texture_bytes(panorama) {
        need.add("the panorama", keep + keep / 3);
        need.add("decoding the panorama", decode);
    }
    if let Ok(meta) = exr::meta::MetaData::read_from_file(exr, false) {
        let read: u64 = meta
            .headers
            .iter()
            .map(|h| {
                let px = h.layer_size.area() as u64;
                h.channels
                    .list
                    .iter()
                    .map(|c| px * c.sample_type.bytes_per_sample() as u64)
                    .sum::<u64>()
            })
            .sum();
        need.add("reading the lens map's channels", read);
        if let Some(h) = meta.headers.first() {
            let px = h.layer_size.area() as u64;
            // Directions in f64 and a magnification each; the filtered
            // pixels (RGBA f32) and the output's encoding.
            need.add("the lens map", px * 28);
            need.add("the relensed pixels", px * 16);
            need.add("the output's encoding", px * if exr_out { 16 } else { 3 });
        }
    }
    need
}

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

/// The film's bytes per pixel: XYZ, kept spectra, spectral bloom's bands,
/// the observables.
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
    12 + keep + bands + 4 * cfg.image.observables.len() as u64
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
    if img.adaptive() {
        // Adaptive sampling's state of each pixel while rendering (see
        // `cpu::adaptive`), with its sums: 40 bytes, 4 for the count of
        // finite samples, 24 for a spectral render's XYZ, 80 for the
        // observables. On the GPU: the state, a round's target, and a
        // pass's sums and probes read back (16 and 128 bytes).
        let per = if job.gpu {
            40 + 4 + 16 + 128
        } else {
            44 + if cfg.spectral.enabled { 24 } else { 0 }
                + if img.observables.is_empty() { 0 } else { 80 }
        };
        let rows = (job.rows + 2 * crate::adaptive::MARGIN).min(img.height) as u64;
        need.add("adaptive sampling's state", per * img.width as u64 * rows);
    }
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
            + img.observables.len() as u64
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
