//! Renders split over jobs: tiles merged into the very bytes of a single
//! render (antialiasing, adaptive sampling, spectral layers, spectral
//! bloom, stereo, both backends), bad tile sets refused by name with
//! nothing written, and animation frames that refuse to mix scenes.

mod common;

use common::{case, gpu, run, small_scene_text};
use std::path::Path;

fn ok(dir: &Path, args: &[&str]) -> String {
    let (code, err) = run(dir, args);
    assert_eq!(code, 0, "{args:?}: {err}");
    err
}

/// The small scene (64 x 48) spectral, 4 samples per pixel (uniformly), with kept
/// spectra in its EXR and spectral bloom: everything a tile carries.
fn full_text() -> String {
    small_scene_text().replace(
        "png = \"out.png\"",
        "png = \"out.png\"\nexr = \"out.exr\"\nsamples = 4\nadaptive = false\nobservables = [\"g\", \"radius\", \"order\", \"time\", \"class\"]",
    ) + r#"
[spectral]
enabled = true
wavelengths = 41
exr_layers = true
doppler = true
beaming = true

[bloom]
strength = 0.2
radius = 0.05
spectral = true
"#
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Renders `text` whole in one folder and as `n` tiles, merged, in
/// another; every file the render writes must be the same bytes.
fn tiles_match_whole(text: &str, n: u32, extra: &[&str], files: &[&str]) {
    let (whole, tiled) = (case(text), case(text));
    let mut args = vec!["render", "-q", "scene.toml"];
    args.extend(extra);
    ok(whole.path(), &args);
    for i in 0..n {
        let tile = format!("{i}/{n}");
        let mut a = args.clone();
        a.extend(["--tile", tile.as_str()]);
        // Thread counts differ between jobs; pixels must not.
        let threads = (1 + i % 3).to_string();
        a.extend(["--threads", threads.as_str()]);
        ok(tiled.path(), &a);
        assert!(
            !tiled.path().join("out.png").exists(),
            "a tile writes no image"
        );
    }
    let mut m = vec!["merge", "scene.toml"];
    m.extend(
        extra
            .iter()
            .filter(|a| !a.starts_with("--backend") && **a != "gpu"),
    );
    let err = ok(tiled.path(), &m);
    assert!(err.contains(&format!("merged {n} tile(s)")), "{err}");
    for f in files {
        assert!(
            read(&whole.path().join(f)) == read(&tiled.path().join(f)),
            "{f} differs after merging {n} tiles"
        );
    }
}

#[test]
fn merged_tiles_are_the_single_render_byte_for_byte() {
    let text = full_text();
    // One tile and uneven bands; then one row per tile, of a strip 12
    // rows high (a process per row).
    for n in [1, 5] {
        tiles_match_whole(&text, n, &[], &["out.png", "out.exr"]);
    }
    let strip = text.replacen("height = 48", "height = 12", 1);
    assert_ne!(strip, text);
    tiles_match_whole(&strip, 12, &[], &["out.png", "out.exr"]);
}

#[test]
fn merged_adaptive_tiles_are_the_single_render_byte_for_byte() {
    // Adaptive sampling decides from a pixel's neighbours: a tile samples
    // rows beyond its own so that its refinement is the whole render's.
    let text = full_text().replacen("adaptive = false", "adaptive = true", 1);
    // Uneven bands; then bands thinner than the rows sampled around
    // them, two rows each of a strip 12 rows high.
    tiles_match_whole(&text, 5, &[], &["out.png", "out.exr"]);
    let strip = text.replacen("height = 48", "height = 12", 1);
    assert_ne!(strip, text);
    tiles_match_whole(&strip, 6, &[], &["out.png", "out.exr"]);
}

#[test]
fn merged_stereo_tiles_give_every_stereo_file() {
    let text = small_scene_text() + "\n[stereo]\nseparation = 1.0e10\nconvergence = 2.2e11\n";
    tiles_match_whole(
        &text,
        3,
        &[],
        &[
            "out.png",
            "out_left.png",
            "out_right.png",
            "out_side_by_side.png",
            "out_anaglyph.png",
        ],
    );
}

#[test]
fn gpu_tiles_merge_into_the_gpu_render() {
    if gpu().is_none() {
        return;
    }
    tiles_match_whole(
        &full_text(),
        4,
        &["--backend", "gpu"],
        &["out.png", "out.exr"],
    );
}

#[test]
fn gpu_adaptive_tiles_merge_into_the_gpu_render() {
    if gpu().is_none() {
        return;
    }
    // Spectral, kept spectra, spectral bloom and every observable, with
    // the rows around each tile traced and refined on the GPU.
    let text = full_text().replacen("adaptive = false", "adaptive = true", 1);
    tiles_match_whole(&text, 3, &["--backend", "gpu"], &["out.png", "out.exr"]);
}

#[test]
fn a_tile_holds_its_rows_place_counts_and_scene() {
    let dir = case(&full_text());
    let d = dir.path();
    let err = ok(d, &["render", "scene.toml", "--tile", "1/3"]);
    assert!(err.contains("tile 1 of 3, rows 16..31 of 64x48"), "{err}");
    let tile = blackhole::tiles::read_tile(&d.join("out.tile-1-of-3.exr")).unwrap();
    assert_eq!((tile.index, tile.count), (1, 3));
    assert_eq!(
        (tile.width, tile.height, tile.rows.clone()),
        (64, 48, 16..32)
    );
    assert_eq!(tile.backend, "cpu");
    let v = &tile.views[0];
    assert_eq!(v.name, "main");
    assert_eq!((v.film.width, v.film.height), (64, 16));
    assert_eq!(v.stats.samples, 64 * 16 * 4);
    assert_eq!(v.film.spectra.as_ref().unwrap().len(), 64 * 16 * 41);
    assert_eq!(v.film.bands.as_ref().unwrap().len(), blackhole::film::BANDS);
    let cfg = blackhole::config::SceneConfig::load(&d.join("scene.toml"), &[]).unwrap();
    assert_eq!(
        tile.scene,
        blackhole::tiles::scene_hash(&cfg, None).unwrap()
    );
    // The rows are the whole render's rows 16..31, bit for bit.
    let scene = blackhole::scene::Scene::build(cfg).unwrap();
    let (whole, _) = scene.render(&|_| {});
    assert!(whole.xyz[64 * 16..64 * 32] == v.film.xyz[..]);
    // The EXR's data window places it in the image.
    let meta = exr::meta::MetaData::read_from_file(d.join("out.tile-1-of-3.exr"), false).unwrap();
    let h = &meta.headers[0];
    assert_eq!(h.own_attributes.layer_position, exr::math::Vec2(0, 16));
    assert_eq!(h.layer_size, exr::math::Vec2(64, 16));
    assert_eq!(
        h.shared_attributes.display_window.size,
        exr::math::Vec2(64, 48)
    );
}

#[test]
fn bad_tile_numbers_are_named_and_write_nothing() {
    let dir = case(&small_scene_text());
    let d = dir.path();
    for (tile, needle) in [
        ("4/4", "below N"),
        ("0/0", "at least 1"),
        ("0/49", "48 rows"),
    ] {
        let (code, err) = run(d, &["render", "scene.toml", "--tile", tile]);
        assert_eq!(code, 1, "{tile}: {err}");
        assert!(err.contains(needle) && err.contains(tile), "{tile}: {err}");
    }
    let (code, err) = run(d, &["render", "scene.toml", "--tile", "x/4"]);
    assert_eq!(code, 2, "{err}");
    let (code, err) = run(d, &["compare", "scene.toml", "--tile", "0/2"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--tile is for render"), "{err}");
    let names: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "only the scene file: {names:?}");
}

/// A folder with tiles 0..n of the small scene rendered.
fn tiled(n: u32) -> tempfile::TempDir {
    let dir = case(&small_scene_text());
    for i in 0..n {
        ok(
            dir.path(),
            &["render", "-q", "scene.toml", "--tile", &format!("{i}/{n}")],
        );
    }
    dir
}

/// Merges in `d`, expecting a failure naming all of `needles`, and no image.
fn merge_fails(d: &Path, extra: &[&str], needles: &[&str]) {
    let mut args = vec!["merge", "scene.toml"];
    args.extend(extra);
    let (code, err) = run(d, &args);
    assert_eq!(code, 1, "{err}");
    for n in needles {
        assert!(err.contains(n), "expected {n:?} in: {err}");
    }
    assert!(!d.join("out.png").exists(), "merge wrote an image: {err}");
}

#[test]
fn incomplete_mixed_foreign_and_damaged_sets_are_refused() {
    // No tiles at all.
    merge_fails(
        case(&small_scene_text()).path(),
        &[],
        &["no tiles", "out.tile-I-of-N.exr"],
    );
    // A missing tile.
    let dir = tiled(3);
    let d = dir.path();
    std::fs::remove_file(d.join("out.tile-1-of-3.exr")).unwrap();
    merge_fails(d, &[], &["missing 1 of 3", "out.tile-1-of-3.exr"]);
    // An extra tile from another split.
    let dir = tiled(2);
    let d = dir.path();
    ok(d, &["render", "-q", "scene.toml", "--tile", "0/3"]);
    merge_fails(d, &[], &["different splits", "N = 2", "N = 3"]);
    // An index beyond N.
    let dir = tiled(2);
    let d = dir.path();
    std::fs::copy(d.join("out.tile-1-of-2.exr"), d.join("out.tile-2-of-2.exr")).unwrap();
    merge_fails(d, &[], &["extra tiles", "out.tile-2-of-2.exr"]);
    // A tile renamed to another place.
    let dir = tiled(2);
    let d = dir.path();
    std::fs::copy(d.join("out.tile-1-of-2.exr"), d.join("out.tile-0-of-2.exr")).unwrap();
    merge_fails(d, &[], &["holds tile 1/2", "0/2"]);
    // Tiles of another config: another exposure, another size.
    let dir = tiled(2);
    let d = dir.path();
    ok(
        d,
        &[
            "render",
            "-q",
            "scene.toml",
            "--tile",
            "1/2",
            "--set",
            "image.exposure=1.0",
            "--overwrite",
        ],
    );
    merge_fails(d, &[], &["out.tile-1-of-2.exr belongs to another scene"]);
    merge_fails(
        tiled(2).path(),
        &["--set", "image.width=65"],
        &["belongs to another scene"],
    );
    // A time is refused by name, as render refuses it: without an
    // [animation], and not finite.
    for t in ["5", "nan", "inf"] {
        merge_fails(tiled(2).path(), &["--time", t], &["--time", "[animation]"]);
    }
    let dir = case(&animated_text());
    for t in ["nan", "inf"] {
        merge_fails(
            dir.path(),
            &["--time", t],
            &["--time", "expected a finite time"],
        );
    }
    // A truncated tile (a copy cut mid-write) and one with a changed byte
    // in its pixels.
    let dir = tiled(2);
    let d = dir.path();
    let p = d.join("out.tile-0-of-2.exr");
    let bytes = read(&p);
    std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
    merge_fails(d, &[], &["out.tile-0-of-2.exr", "render it again"]);
    let mut damaged = bytes.clone();
    let at = damaged.len() - 200;
    damaged[at] ^= 0x40;
    std::fs::write(&p, &damaged).unwrap();
    merge_fails(d, &[], &["out.tile-0-of-2.exr", "render it again"]);
    // Its facts edited (a count in the header's text, the same length) and
    // its scene hash damaged: both are under the tile's hash.
    for from in ["sky=", "scene="] {
        let mut edited = bytes.clone();
        let at = edited
            .windows(from.len())
            .position(|w| w == from.as_bytes())
            .unwrap()
            + from.len();
        edited[at] = if edited[at] == b'1' { b'2' } else { b'1' };
        std::fs::write(&p, &edited).unwrap();
        merge_fails(
            d,
            &[],
            &["out.tile-0-of-2.exr", "edited", "render it again"],
        );
    }
    // The set is whole again: it merges.
    std::fs::write(&p, &bytes).unwrap();
    ok(d, &["merge", "-q", "scene.toml"]);
    assert!(d.join("out.png").exists());
    // A copy of a tile under another spelling of its number is refused,
    // not merged twice.
    for copy in ["out.tile-01-of-2.exr", "out.tile-1-of-02.exr"] {
        std::fs::copy(d.join("out.tile-1-of-2.exr"), d.join(copy)).unwrap();
        std::fs::remove_file(d.join("out.png")).unwrap_or(());
        merge_fails(
            d,
            &[],
            &[copy, "named like tile 1/2", "out.tile-1-of-2.exr"],
        );
        std::fs::remove_file(d.join(copy)).unwrap();
    }
}

#[test]
fn tiles_from_both_backends_do_not_mix() {
    if gpu().is_none() {
        return;
    }
    let dir = case(&small_scene_text());
    let d = dir.path();
    ok(d, &["render", "-q", "scene.toml", "--tile", "0/2"]);
    ok(
        d,
        &[
            "render",
            "-q",
            "scene.toml",
            "--tile",
            "1/2",
            "--backend",
            "gpu",
        ],
    );
    merge_fails(d, &[], &["out.tile-1-of-2.exr was rendered on gpu", "cpu"]);
}

/// The small scene animated over 4 frames.
fn animated_text() -> String {
    small_scene_text()
        + r#"
[animation]
frames = 4
fps = 8.0
duration = 2000.0
"#
}

fn frame(d: &Path, k: u32) -> std::path::PathBuf {
    d.join(format!("out_{k:05}.png"))
}

#[test]
fn frame_runs_cover_the_animation_and_frames_never_mix_scenes() {
    let text = animated_text();
    let (whole, runs) = (case(&text), case(&text));
    ok(whole.path(), &["animate", "-q", "scene.toml"]);
    // Three runs of 4 frames: 0..0, 1..1, 2..3.
    for i in 0..3 {
        ok(
            runs.path(),
            &[
                "animate",
                "-q",
                "--no-video",
                "scene.toml",
                "--frames",
                &format!("{i}/3"),
            ],
        );
    }
    for k in 0..4 {
        assert!(
            read(&frame(whole.path(), k)) == read(&frame(runs.path(), k)),
            "frame {k}"
        );
        let tag = blackhole::output::png_text(&frame(runs.path(), k), "blackhole:frame").unwrap();
        assert_eq!(tag, Some(k.to_string()));
    }
    for (frames, needle) in [
        ("4/4", "0 <= I < N"),
        ("0/5", "at most 4 runs"),
        ("0..4", "has 4 frames"),
    ] {
        let (code, err) = run(runs.path(), &["animate", "scene.toml", "--frames", frames]);
        assert_eq!(code, 1, "{frames}: {err}");
        assert!(err.contains(needle), "{frames}: {err}");
    }
    // The same frames with another exposure are another scene's: resuming
    // refuses them by name, --overwrite renders them again.
    let d = runs.path();
    let (code, err) = run(d, &["animate", "scene.toml", "--set", "image.exposure=1.0"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("out_00000.png is not frame 0 of this scene"),
        "{err}"
    );
    ok(
        d,
        &[
            "animate",
            "-q",
            "scene.toml",
            "--set",
            "image.exposure=1.0",
            "--overwrite",
        ],
    );
    assert!(read(&frame(whole.path(), 2)) != read(&frame(d, 2)));
    // A frame copied over another's place is refused too.
    std::fs::copy(frame(d, 1), frame(d, 2)).unwrap();
    let (code, err) = run(d, &["animate", "scene.toml", "--set", "image.exposure=1.0"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("out_00002.png is not frame 2"), "{err}");
}

#[test]
fn a_complete_tile_is_kept_and_a_foreign_one_named() {
    let dir = case(&small_scene_text());
    let d = dir.path();
    let tile = d.join("out.tile-0-of-2.exr");
    ok(d, &["render", "-q", "scene.toml", "--tile", "0/2"]);
    let (bytes, when) = (
        read(&tile),
        std::fs::metadata(&tile).unwrap().modified().unwrap(),
    );
    let err = ok(d, &["render", "scene.toml", "--tile", "0/2"]);
    assert!(err.contains("tile 0/2 is complete: kept"), "{err}");
    assert_eq!(std::fs::metadata(&tile).unwrap().modified().unwrap(), when);
    // Another scene's tile at that name is not taken for this one's.
    let other = |extra: &[&str]| {
        let mut args = vec!["render", "-q", "scene.toml", "--tile", "0/2"];
        args.extend(["--set", "image.exposure=1.0"]);
        args.extend(extra);
        run(d, &args)
    };
    let (code, err) = other(&[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("not tile 0/2 of this scene") && err.contains("--overwrite"),
        "{err}"
    );
    assert_eq!(read(&tile), bytes);
    let (code, err) = other(&["--overwrite"]);
    assert_eq!(code, 0, "{err}");
    assert_ne!(read(&tile), bytes);
}
