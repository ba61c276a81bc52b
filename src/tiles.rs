//! A render split over jobs: tile I of N is a band of the image's rows,
//! rendered alone (`render --tile I/N`) into an EXR file that holds its
//! linear film (float32 XYZ, and the spectra and bloom bands the scene
//! keeps), its place in the image as the data window, the render's counts
//! and the hash of the scene it belongs to; `merge` checks a set of them
//! and assembles the film a single render gives, bit for bit.
//!
//! Every pixel's samples are seeded by its place in the whole image and
//! nothing in the film depends on its neighbours, so the rows of a tile
//! are exactly the rows of a whole render; post-processing (bloom, tone
//! mapping, the files) runs once on the assembled film.

use crate::config::SceneConfig;
use crate::film::{BANDS, Film, Stats, band_centres};
use anyhow::{Context, Result, anyhow, bail};
use exr::prelude::*;
use sha2::{Digest, Sha256};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Rows of tile `i` of `n` of an image `height` rows high: consecutive
/// bands whose heights differ by at most one row, top to bottom.
pub fn tile_rows(height: u32, i: u32, n: u32) -> Range<u32> {
    let at = |k: u32| (k as u64 * height as u64 / n as u64) as u32;
    at(i)..at(i + 1)
}

/// Checks `--tile I/N` against an image `height` rows high.
pub fn check_tile(i: u32, n: u32, height: u32) -> Result<()> {
    if n == 0 {
        bail!("--tile {i}/{n}: N, the number of tiles, must be at least 1");
    }
    if i >= n {
        bail!(
            "--tile {i}/{n}: I is 0-based and must be below N (0 to {})",
            n - 1
        );
    }
    if n > height {
        bail!(
            "--tile {i}/{n}: the image has {height} rows, so it splits into at most {height} tiles (bands of rows)"
        );
    }
    Ok(())
}

/// `<stem>.tile-<I>-of-<N>.exr` beside `png`.
pub fn tile_path(png: &Path, i: u32, n: u32) -> PathBuf {
    png.with_file_name(format!("{}.tile-{i}-of-{n}.exr", stem(png)))
}

fn stem(png: &Path) -> String {
    png.file_stem()
        .map_or_else(|| "image".into(), |s| s.to_string_lossy().into_owned())
}

/// The (I, N) of a file name `<stem>.tile-<I>-of-<N>.exr`, and whether it
/// is written as `render` names tiles (no leading zeros): `tile-01-of-4`
/// is tile 1 too, a copy that must not count twice.
fn parse_tile_name(name: &str, stem: &str) -> Option<(u32, u32, bool)> {
    let rest = name.strip_prefix(stem)?.strip_prefix(".tile-")?;
    let rest = rest.strip_suffix(".exr")?;
    let (i, n) = rest.split_once("-of-")?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(i) || !digits(n) {
        return None;
    }
    let (i, n): (u32, u32) = (i.parse().ok()?, n.parse().ok()?);
    let canonical = name == format!("{stem}.tile-{i}-of-{n}.exr");
    Some((i, n, canonical))
}

/// The SHA-256 (hex) of everything that decides a scene's pixels: the
/// resolved configuration (defaults filled in, paths absolute) but for
/// its output file names, the instant rendered (`render --time`), the
/// program's version and the bytes of every input file (textures, the
/// spectral set's manifest and images, the star catalogue, meshes).
pub fn scene_hash(cfg: &SceneConfig, time: Option<f64>) -> Result<String> {
    let mut c = cfg.clone();
    let mut h = Sha256::new();
    h.update(format!("blackhole {} scene\n", env!("CARGO_PKG_VERSION")));
    h.update(format!("time {time:?}\n"));
    let mut inputs = Vec::new();
    for (key, path) in c.paths_mut() {
        if matches!(key.as_str(), "image.png" | "image.exr" | "animation.video") {
            // Where the results go does not change them.
            *path = PathBuf::new();
        } else {
            inputs.push((key, path.clone()));
        }
    }
    h.update(format!("{c:?}\n"));
    for (key, path) in inputs {
        let mut files = vec![path.clone()];
        if key == "disk.spectrum" {
            files.extend(crate::spectral_texture::manifest_files(&path)?);
        }
        for f in files {
            let bytes = std::fs::read(&f).with_context(|| {
                format!("cannot read {} ({key}) to hash the scene", f.display())
            })?;
            h.update(format!("{key} {} {}\n", f.display(), bytes.len()));
            h.update(&bytes);
        }
    }
    Ok(hex(&h.finalize()))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// One view's rows in a tile: the film and the counts of rendering it.
#[derive(Clone, Debug)]
pub struct View {
    /// `main`, or `left` and `right` for the eyes of `[stereo]`.
    pub name: String,
    /// The tile's rows of the view's film.
    pub film: Film,
    /// Counts of those rows.
    pub stats: Stats,
}

/// A tile: a band of rows of every view of a render.
#[derive(Clone, Debug)]
pub struct Tile {
    /// I of `--tile I/N`.
    pub index: u32,
    /// N of `--tile I/N`.
    pub count: u32,
    /// The whole image's size.
    pub width: u32,
    pub height: u32,
    /// The image's rows this tile holds.
    pub rows: Range<u32>,
    /// [`scene_hash`] of the scene rendered.
    pub scene: String,
    /// `cpu`, or `gpu` and the device's name.
    pub backend: String,
    /// Wall time of the tile's render (s).
    pub seconds: f64,
    pub views: Vec<View>,
}

/// The one attribute that carries a tile's facts, as `key=value` lines
/// (one attribute: exr writes several in a random order).
const ATTRIBUTE: &str = "blackhole:tile";
const KEY_SCENE: &str = "scene";
const KEY_TILE: &str = "tile";
const KEY_IMAGE: &str = "image";
const KEY_BACKEND: &str = "backend";
const KEY_SECONDS: &str = "seconds";
const KEY_NM: &str = "nm";
/// An observed scene's frequencies (Hz), comma-separated.
const KEY_HZ: &str = "hz";
const KEY_STATS: &str = "stats";
const KEY_DATA: &str = "data";

/// The film's planes as named float32 channels, in the file's (sorted)
/// order.
fn channels(film: &Film) -> Vec<(String, Vec<f32>)> {
    let mut ch = Vec::new();
    for (c, name) in ["X", "Y", "Z"].iter().enumerate() {
        ch.push((name.to_string(), film.xyz.iter().map(|v| v[c]).collect()));
    }
    if let Some(spectra) = &film.spectra {
        let names = film.channel_names();
        let n = names.len();
        for (k, name) in names.into_iter().enumerate() {
            ch.push((name, spectra.iter().skip(k).step_by(n).copied().collect()));
        }
    }
    if let Some(bands) = &film.bands {
        for (b, (_, plane)) in bands.iter().enumerate() {
            for (c, name) in ["X", "Y", "Z"].iter().enumerate() {
                ch.push((
                    format!("band{b}.{name}"),
                    plane.iter().map(|v| v[c]).collect(),
                ));
            }
        }
    }
    for (o, plane) in &film.observables {
        ch.push((o.channel(), plane.clone()));
    }
    ch.sort_by(|a, b| a.0.cmp(&b.0));
    ch
}

/// SHA-256 of the tile's facts (every line of its attribute but the hash
/// itself) and its channels (names and little-endian values), in order:
/// neither the pixels nor what is said about them can change unnoticed.
fn data_hash<'a>(facts: &str, channels: impl Iterator<Item = (&'a str, &'a [f32])>) -> String {
    let mut h = Sha256::new();
    h.update(facts.as_bytes());
    h.update([0]);
    for (name, values) in channels {
        h.update(name.as_bytes());
        h.update([0]);
        for v in values {
            h.update(v.to_le_bytes());
        }
    }
    hex(&h.finalize())
}

fn stats_text(s: &Stats) -> String {
    format!(
        "samples={} rays={} steps={} disk={} objects={} sky={} captured={} abandoned={} non_finite={} closed={} g_min={:?} g_max={:?} refined={} extra={}",
        s.samples,
        s.rays,
        s.steps,
        s.disk,
        s.objects,
        s.sky,
        s.captured,
        s.abandoned,
        s.non_finite,
        s.closed,
        s.g_min,
        s.g_max,
        s.refined,
        s.extra
    )
}

fn parse_stats(text: &str) -> Option<Stats> {
    let mut s = Stats::default();
    let mut seen = 0;
    for part in text.split_whitespace() {
        let (k, v) = part.split_once('=')?;
        let int = || v.parse::<u64>().ok();
        match k {
            "samples" => s.samples = int()?,
            "rays" => s.rays = int()?,
            "steps" => s.steps = int()?,
            "disk" => s.disk = int()?,
            "objects" => s.objects = int()?,
            "sky" => s.sky = int()?,
            "captured" => s.captured = int()?,
            "abandoned" => s.abandoned = int()?,
            "non_finite" => s.non_finite = int()?,
            "closed" => s.closed = int()?,
            "g_min" => s.g_min = v.parse().ok()?,
            "g_max" => s.g_max = v.parse().ok()?,
            "refined" => s.refined = int()?,
            "extra" => s.extra = int()?,
            _ => return None,
        }
        // Tiles written before adaptive sampling have neither of its two.
        seen += !matches!(k, "refined" | "extra") as u32;
    }
    (seen == 12).then_some(s)
}

fn text(s: &str) -> AttributeValue {
    AttributeValue::Text(Text::from(s))
}

/// Writes `tile` to `path` atomically (a temporary file renamed into
/// place: an interrupted job leaves no partial tile).
pub fn write_tile(path: &Path, tile: &Tile) -> Result<()> {
    let list = |f: fn(&Film) -> &Vec<f64>| {
        tile.views
            .first()
            .map(|v| {
                f(&v.film)
                    .iter()
                    .map(|x| format!("{x:?}"))
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .unwrap_or_default()
    };
    let (nm, hz) = (list(|f| &f.nm), list(|f| &f.frequencies));
    let mut layers = Vec::new();
    for view in &tile.views {
        let film = &view.film;
        let ch = channels(film);
        let mut attrs = LayerAttributes::named(view.name.as_str());
        attrs.layer_position = Vec2(0, tile.rows.start as i32);
        let facts = [
            (KEY_SCENE, tile.scene.clone()),
            (KEY_TILE, format!("{}/{}", tile.index, tile.count)),
            (KEY_IMAGE, format!("{}x{}", tile.width, tile.height)),
            (KEY_BACKEND, tile.backend.clone()),
            (KEY_SECONDS, format!("{:?}", tile.seconds)),
            (KEY_NM, nm.clone()),
            (KEY_HZ, hz.clone()),
            (KEY_STATS, stats_text(&view.stats)),
        ]
        .map(|(k, v)| format!("{k}={v}\n"))
        .concat();
        let data = data_hash(&facts, ch.iter().map(|(n, v)| (n.as_str(), v.as_slice())));
        let facts = format!("{facts}{KEY_DATA}={data}\n");
        attrs.other.insert(Text::from(ATTRIBUTE), text(&facts));
        let list: Vec<AnyChannel<FlatSamples>> = ch
            .into_iter()
            .map(|(name, v)| AnyChannel::new(name.as_str(), FlatSamples::F32(v)))
            .collect();
        layers.push(Layer::new(
            (film.width as usize, film.height as usize),
            attrs,
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(list)),
        ));
    }
    let image = Image::from_layers(
        ImageAttributes::new(IntegerBounds::new(
            (0, 0),
            (tile.width as usize, tile.height as usize),
        )),
        layers,
    );
    crate::output::write_atomic(path, |w| {
        image.write().non_parallel().to_buffered(w)?;
        Ok(())
    })
}

/// Reads a tile and checks it is whole: every attribute present and
/// well-formed, the pixels hashing to what was written.
pub fn read_tile(path: &Path) -> Result<Tile> {
    let bad = |what: &str| not_a_tile(path, what);
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .map_err(|e| {
            anyhow!(
                "{}: cannot read the tile ({e}); it is damaged or incomplete: render it again",
                path.display()
            )
        })?;
    let mut tile: Option<Tile> = None;
    for layer in &image.layer_data {
        let this = read_layer(path, layer)?;
        match &mut tile {
            None => tile = Some(this),
            Some(t) => {
                let same = (t.index, t.count, t.width, t.height, &t.rows, &t.scene)
                    == (
                        this.index,
                        this.count,
                        this.width,
                        this.height,
                        &this.rows,
                        &this.scene,
                    );
                if !same {
                    return Err(bad("layers that disagree"));
                }
                t.views.extend(this.views);
            }
        }
    }
    tile.ok_or_else(|| bad("no layers"))
}

/// The error for a file that is not a tile: names the file and what is wrong.
fn not_a_tile(path: &Path, what: &str) -> anyhow::Error {
    anyhow!("{}: not a blackhole tile ({what})", path.display())
}

/// One layer of a tile file as a tile of one view: its facts, and its
/// pixels checked against the hash written with them.
fn read_layer(path: &Path, layer: &Layer<AnyChannels<FlatSamples>>) -> Result<Tile> {
    let bad = |what: &str| not_a_tile(path, what);
    let a = &layer.attributes;
    let facts = match a.other.get(&Text::from(ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => t.to_string(),
        _ => return Err(bad(&format!("no {ATTRIBUTE} attribute"))),
    };
    let get = |k: &str| -> Result<String> {
        facts
            .lines()
            .find_map(|l| l.strip_prefix(k)?.strip_prefix('='))
            .map(str::to_string)
            .ok_or_else(|| bad(&format!("no {k} in its {ATTRIBUTE} attribute")))
    };
    let name = a
        .layer_name
        .as_ref()
        .map(|t| t.to_string())
        .ok_or_else(|| bad("a layer without a name"))?;
    let (index, count) = get(KEY_TILE)?
        .split_once('/')
        .and_then(|(i, n)| Some((i.parse().ok()?, n.parse().ok()?)))
        .ok_or_else(|| bad("malformed tile number"))?;
    let (width, height) = get(KEY_IMAGE)?
        .split_once('x')
        .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
        .ok_or_else(|| bad("malformed image size"))?;
    let numbers = |s: &str, what: &str| -> Result<Vec<f64>> {
        match s {
            "" => Ok(Vec::new()),
            s => s
                .split(',')
                .map(|x| x.parse().map_err(|_| bad(what)))
                .collect(),
        }
    };
    let nm = numbers(&get(KEY_NM)?, "malformed wavelengths")?;
    let hz = numbers(&get(KEY_HZ)?, "malformed frequencies")?;
    let stats = parse_stats(&get(KEY_STATS)?).ok_or_else(|| bad("malformed statistics"))?;
    let seconds: f64 = get(KEY_SECONDS)?
        .parse()
        .map_err(|_| bad("malformed time"))?;
    let (w, rows_n) = (layer.size.0, layer.size.1);
    let y0 = a.layer_position.1;
    if a.layer_position.0 != 0 || y0 < 0 || w != width as usize {
        return Err(bad("a data window that is not a band of whole rows"));
    }
    let rows = y0 as u32..y0 as u32 + rows_n as u32;
    let mut planes = Vec::new();
    for ch in &layer.channel_data.list {
        let FlatSamples::F32(v) = &ch.sample_data else {
            return Err(bad("a channel that is not float32"));
        };
        planes.push((ch.name.to_string(), v.as_slice()));
    }
    let said: String = facts
        .lines()
        .filter(|l| !l.starts_with(&format!("{KEY_DATA}=")))
        .map(|l| format!("{l}\n"))
        .collect();
    let data = data_hash(&said, planes.iter().map(|(n, v)| (n.as_str(), *v)));
    if data != get(KEY_DATA)? {
        bail!(
            "{}: the tile's pixels or facts do not match the hash written with them (damaged or edited file): render it again",
            path.display()
        );
    }
    let film = layer_film(path, &planes, (nm, hz), width, rows_n as u32)?;
    let view = View { name, film, stats };
    Ok(Tile {
        index,
        count,
        width,
        height,
        rows,
        scene: get(KEY_SCENE)?,
        backend: get(KEY_BACKEND)?,
        seconds,
        views: vec![view],
    })
}

/// The film of one layer from its float32 planes, named as `write_tile`
/// names them; `rows` is the layer's height.
fn layer_film(
    path: &Path,
    planes: &[(String, &[f32])],
    (nm, frequencies): (Vec<f64>, Vec<f64>),
    width: u32,
    rows: u32,
) -> Result<Film> {
    let bad = |what: &str| not_a_tile(path, what);
    let plane = |n: &str| {
        planes
            .iter()
            .find(|(name, _)| name == n)
            .map(|(_, v)| *v)
            .ok_or_else(|| bad(&format!("no channel {n}")))
    };
    let xyz3 = |prefix: &str| -> Result<Vec<glam::Vec3>> {
        let (x, y, z) = (
            plane(&format!("{prefix}X"))?,
            plane(&format!("{prefix}Y"))?,
            plane(&format!("{prefix}Z"))?,
        );
        Ok((0..x.len())
            .map(|i| glam::Vec3::new(x[i], y[i], z[i]))
            .collect())
    };
    let xyz = xyz3("")?;
    let has_spectra = planes
        .iter()
        .any(|(n, _)| n.starts_with("S0.") || n.starts_with("jy."));
    let names = crate::film::channel_names(&nm, &frequencies);
    let spectra = if has_spectra {
        let cols: Vec<&[f32]> = names.iter().map(|n| plane(n)).collect::<Result<_>>()?;
        let mut s = Vec::with_capacity(xyz.len() * names.len());
        for i in 0..xyz.len() {
            s.extend(cols.iter().map(|c| c[i]));
        }
        Some(s)
    } else {
        None
    };
    let bands = if planes.iter().any(|(n, _)| n.starts_with("band")) {
        let centres = band_centres(&nm);
        Some(
            (0..BANDS)
                .map(|b| Ok((centres[b], xyz3(&format!("band{b}."))?)))
                .collect::<Result<Vec<_>>>()?,
        )
    } else {
        None
    };
    // The observables in the order the file names them (the scene's
    // is checked when the tiles are merged: the hash covers it).
    let mut observables = Vec::new();
    for (n, v) in planes {
        if let Some(name) = n.strip_prefix("obs.") {
            let o = crate::film::Observable::from_name(name)
                .ok_or_else(|| bad(&format!("an unknown observable channel {n}")))?;
            observables.push((o, v.to_vec()));
        }
    }
    Ok(Film {
        width,
        height: rows,
        xyz,
        nm,
        frequencies,
        spectra,
        bands,
        bloomed: None,
        observables,
    })
}

/// The tiles of a render whose `image.png` is `png`: every
/// `<stem>.tile-<I>-of-<N>.exr` beside it, which must be one whole set
/// (one N, every I from 0 to N-1). Sorted by I.
pub fn find_tiles(png: &Path) -> Result<Vec<(u32, u32, PathBuf)>> {
    let dir = match png.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let stem = stem(png);
    let mut found = Vec::new();
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))?;
    for e in entries {
        let e = e.with_context(|| format!("cannot list {}", dir.display()))?;
        let name = e.file_name().to_string_lossy().into_owned();
        match parse_tile_name(&name, &stem) {
            Some((i, n, true)) => found.push((i, n, e.path())),
            Some((i, n, false)) => bail!(
                "{} is named like tile {i}/{n} but not as render names it ({}): a copy or a renamed file; remove it",
                e.path().display(),
                tile_path(png, i, n).display()
            ),
            None => {}
        }
    }
    found.sort();
    let pattern = dir.join(format!("{stem}.tile-I-of-N.exr"));
    let Some(&(_, n, _)) = found.first() else {
        bail!(
            "no tiles to merge: no file {} (render them with `blackhole render CONFIG --tile I/N`)",
            pattern.display()
        );
    };
    let counts: std::collections::BTreeSet<u32> = found.iter().map(|t| t.1).collect();
    if counts.len() > 1 {
        let list: Vec<String> = counts.iter().map(|c| format!("N = {c}")).collect();
        bail!(
            "tiles of different splits beside {}: {} (extra tiles from another run; remove the set that is not wanted)",
            png.display(),
            list.join(", ")
        );
    }
    let extra: Vec<String> = found
        .iter()
        .filter(|t| t.0 >= n)
        .map(|t| t.2.display().to_string())
        .collect();
    if !extra.is_empty() {
        bail!(
            "extra tiles: {} (I must be below N = {n})",
            extra.join(", ")
        );
    }
    let missing: Vec<String> = (0..n)
        .filter(|i| !found.iter().any(|t| t.0 == *i))
        .map(|i| tile_path(png, i, n).display().to_string())
        .collect();
    if !missing.is_empty() {
        bail!(
            "missing {} of {n} tiles: {}",
            missing.len(),
            missing.join(", ")
        );
    }
    Ok(found)
}

/// Joins one view's films, top to bottom, into the whole image's film.
pub fn join(parts: Vec<Film>) -> Film {
    let mut it = parts.into_iter();
    let mut all = it.next().expect("at least one tile");
    for f in it {
        all.height += f.height;
        all.xyz.extend(f.xyz);
        if let (Some(a), Some(b)) = (all.spectra.as_mut(), f.spectra) {
            a.extend(b);
        }
        if let (Some(a), Some(b)) = (all.bands.as_mut(), f.bands) {
            for ((_, pa), (_, pb)) in a.iter_mut().zip(b) {
                pa.extend(pb);
            }
        }
        for ((_, pa), (_, pb)) in all.observables.iter_mut().zip(f.observables) {
            pa.extend(pb);
        }
    }
    all
}

/// A whole set of tiles read and checked: every view's film assembled,
/// the counts summed, the render times and the backend.
pub struct Merged {
    /// The main view's film and counts.
    pub main: (Film, Stats),
    /// The stereo eyes' films, when the tiles hold them.
    pub eyes: Option<(Film, Film)>,
    /// The tiles' render times added up (s).
    pub seconds: f64,
    /// The backend that rendered them (`cpu`, `gpu: DEVICE`).
    pub backend: String,
}

/// Reads `found` (from [`find_tiles`]) and checks each tile belongs to the
/// scene of `hash` (`config` names it for messages) at `width` x
/// `height`, holds the rows its name says, and that all come from one
/// backend; then joins every view's rows.
pub fn merge(
    found: &[(u32, u32, PathBuf)],
    hash: &str,
    config: &Path,
    width: u32,
    height: u32,
) -> Result<Merged> {
    let (w, h) = (width, height);
    let n = found[0].1;
    let mut views: Vec<(String, Vec<Film>, Stats)> = Vec::new();
    let (mut seconds, mut backend) = (0.0, None::<String>);
    for (i, _, path) in found {
        let tile = read_tile(path)?;
        if tile.scene != hash {
            // Enough digits to tell the two apart.
            let differ = tile
                .scene
                .bytes()
                .zip(hash.bytes())
                .position(|(a, b)| a != b)
                .unwrap_or(0);
            let digits = (differ + 4).clamp(12, hash.len());
            let cut = |h: &str| h.get(..digits.min(h.len())).unwrap_or(h).to_string();
            bail!(
                "{} belongs to another scene (hash {}...) than {} with these settings (hash {}...): render it again from this scene, or merge with the settings it was rendered with (--set, --unset, --time)",
                path.display(),
                cut(&tile.scene),
                config.display(),
                cut(hash)
            );
        }
        if (tile.index, tile.count) != (*i, n) {
            bail!(
                "{} holds tile {}/{}, not the {i}/{n} its name says",
                path.display(),
                tile.index,
                tile.count
            );
        }
        let rows = tile_rows(h, *i, n);
        if (tile.width, tile.height) != (w, h) || tile.rows != rows {
            bail!(
                "{} holds rows {}..{} of a {}x{} image; tile {i}/{n} of {w}x{h} is rows {}..{} (inclusive): render it again from this scene",
                path.display(),
                tile.rows.start,
                tile.rows.end.saturating_sub(1),
                tile.width,
                tile.height,
                rows.start,
                rows.end - 1
            );
        }
        let kind = |b: &str| b.split(':').next().unwrap_or("").to_string();
        match &backend {
            None => backend = Some(tile.backend.clone()),
            Some(b) if kind(b) != kind(&tile.backend) => bail!(
                "{} was rendered on {}, other tiles on {b}: the backends give slightly different pixels, so a set must come from one",
                path.display(),
                tile.backend
            ),
            _ => {}
        }
        seconds += tile.seconds;
        if views.is_empty() {
            views = tile
                .views
                .iter()
                .map(|v| (v.name.clone(), Vec::new(), Stats::default()))
                .collect();
        }
        for v in tile.views {
            let slot = views
                .iter_mut()
                .find(|s| s.0 == v.name)
                .ok_or_else(|| anyhow!("{}: an unexpected view {}", path.display(), v.name))?;
            slot.1.push(v.film);
            slot.2 = slot.2 + v.stats;
        }
    }
    let mut films: Vec<(String, Film, Stats)> = views
        .into_iter()
        .map(|(name, parts, st)| (name, join(parts), st))
        .collect();
    let mut take = |name: &str| {
        films
            .iter()
            .position(|f| f.0 == name)
            .map(|i| films.remove(i))
    };
    let (_, film, stats) = take("main").ok_or_else(|| anyhow!("the tiles hold no main view"))?;
    let eyes = match (take("left"), take("right")) {
        (Some(l), Some(r)) => Some((l.1, r.1)),
        _ => None,
    };
    Ok(Merged {
        main: (film, stats),
        eyes,
        seconds,
        backend: backend.unwrap_or_default(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_rows_once_in_order() {
        for (h, n) in [(1, 1), (7, 3), (10, 10), (1080, 7), (64, 4)] {
            let mut next = 0;
            for i in 0..n {
                let r = tile_rows(h, i, n);
                assert_eq!(r.start, next);
                assert!(r.len() as u32 >= h / n && r.len() as u32 <= h.div_ceil(n));
                next = r.end;
            }
            assert_eq!(next, h);
        }
    }

    #[test]
    fn tile_names_round_trip_and_others_are_ignored() {
        let p = tile_path(Path::new("/x/img.png"), 3, 12);
        assert_eq!(p, Path::new("/x/img.tile-3-of-12.exr"));
        let name = p.file_name().unwrap().to_str().unwrap();
        assert_eq!(parse_tile_name(name, "img"), Some((3, 12, true)));
        assert_eq!(
            parse_tile_name("img.tile-03-of-12.exr", "img"),
            Some((3, 12, false))
        );
        assert_eq!(
            parse_tile_name("img.tile-3-of-012.exr", "img"),
            Some((3, 12, false))
        );
        for other in [
            "img.exr",
            "img.tile-3-of-.exr",
            "img.tile--1-of-4.exr",
            "imgx.tile-1-of-4.exr",
            "img.tile-1-of-4.exr.tmp",
        ] {
            assert_eq!(parse_tile_name(other, "img"), None, "{other}");
        }
    }

    #[test]
    fn bad_tile_numbers_are_named() {
        assert!(check_tile(0, 1, 1).is_ok());
        for (i, n, h, needle) in [
            (0, 0, 10, "at least 1"),
            (4, 4, 10, "below N"),
            (0, 11, 10, "at most 10"),
        ] {
            let e = check_tile(i, n, h).unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains(&format!("{i}/{n}")), "{e}");
        }
    }

    #[test]
    fn statistics_round_trip() {
        let s = Stats {
            samples: 1 << 40,
            rays: 3,
            steps: u64::MAX,
            disk: 1,
            objects: 2,
            sky: 5,
            captured: 6,
            abandoned: 7,
            non_finite: 8,
            closed: 9,
            g_min: 0.123_456_789_012_345_67,
            g_max: f64::NEG_INFINITY,
            refined: 10,
            extra: 11,
        };
        assert_eq!(parse_stats(&stats_text(&s)), Some(s));
        assert_eq!(parse_stats("samples=1"), None);
    }
}
