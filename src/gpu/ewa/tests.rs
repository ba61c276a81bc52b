//! The WGSL footprint lookups (ewa.wgsl) against the CPU's, input by
//! input: a compute entry point of the tests alone (ewa_probe.wgsl)
//! evaluates them on the GPU with a scene packed as renders pack it, and
//! the CPU's functions take the same f32 inputs. Without a GPU adapter the
//! GPU part prints why and passes, unless `CI` is set (CI installs
//! software Vulkan); the probe's shader is validated without one.

use super::super::Gpu;
use super::super::pack::Packed;
use crate::config::{Interpolation, Override, SceneConfig};
use crate::disk::DiskMaterial;
use crate::scene::Scene;
use crate::sky::Sky;
use crate::texture::Footprint;
use glam::{DVec2, DVec3};
use std::path::{Path, PathBuf};

/// What a probe evaluates (ewa_probe.wgsl's kinds).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// ewa_disk: RGBA, or the spectral set's coverage in w.
    Disk = 0,
    /// ewa_disk_set4 at four wavelengths.
    Set4 = 1,
    /// ewa_sky: the panorama.
    Sky = 2,
    /// ewa_stars: luminance, kelvin, Milky Way.
    Stars = 3,
    /// ewa_equirect: u, v, du/dx, dv/dy.
    Equirect = 4,
}

/// One input: texture coordinates (disk) or a direction (sky) in `p`, its
/// derivatives per pixel step, the set's wavelengths.
#[derive(Clone, Copy, Debug)]
struct Probe {
    kind: Kind,
    p: [f32; 3],
    dx: [f32; 3],
    dy: [f32; 3],
    nm: [f32; 4],
    /// What the case is, for messages.
    what: &'static str,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// A shipped scene, 8 x 8, with `sets` on top (`-KEY` removes KEY).
fn scene(name: &str, sets: &[String]) -> Scene {
    let base = ["image.width=8", "image.height=8", "image.samples=1"];
    let overrides: Vec<Override> = base
        .iter()
        .map(|s| s.to_string())
        .chain(sets.iter().cloned())
        .map(|s| match s.strip_prefix('-') {
            Some(key) => Override::unset(key).unwrap(),
            None => Override::parse(&s).unwrap(),
        })
        .collect();
    let path = root().join("configs").join(format!("{name}.toml"));
    Scene::build(SceneConfig::load(&path, &overrides).unwrap()).unwrap()
}

/// A small deterministic generator (SplitMix64) in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Textures with detail at every scale, of sides that are not powers of
/// two (so coarse levels scale their axes unlike): an 8-bit RGBA disk
/// with varying alpha, and a 16-bit panorama (linear texels).
fn write_textures(dir: &Path) -> (PathBuf, PathBuf) {
    let mut rng = Rng(7);
    let disk = image::RgbaImage::from_fn(300, 212, |x, y| {
        let n = (rng.next() * 255.0) as u8;
        let stripe = if (x / 3 + y / 5) % 2 == 0 { 230 } else { 20 };
        let a = (40.0 + 215.0 * (0.5 + 0.5 * (x as f64 * 0.05).sin())) as u8;
        image::Rgba([n, stripe, ((x * 7 + y * 3) % 256) as u8, a])
    });
    let sky = image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_fn(360, 180, |x, y| {
        let n = (rng.next() * 65535.0) as u16;
        let band = if (x / 4 + y / 2) % 3 == 0 {
            60000
        } else {
            3000
        };
        image::Rgb([n, band, ((x * 181 + y * 97) % 65536) as u16])
    });
    let (d, s) = (dir.join("disk.png"), dir.join("sky.png"));
    disk.save(&d).unwrap();
    sky.save(&s).unwrap();
    (d, s)
}

/// A unit tangent frame at unit `d`.
fn frame(d: DVec3) -> (DVec3, DVec3) {
    let t = d.any_orthonormal_vector();
    (t, d.cross(t))
}

fn f3(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Footprints in level-0 texels, as (major, minor, what): magnified,
/// minified on whole and fractional levels, anisotropic below, at and far
/// beyond the cap of 16, and the coarsest level.
const SHAPES: [(f64, f64, &str); 13] = [
    (0.0, 0.0, "a point"),
    (0.3, 0.2, "magnified"),
    (1.0, 1.0, "one texel"),
    (1.7, 1.2, "minified, between levels 0 and 1"),
    (4.0, 4.0, "minified, level 2 exactly"),
    (6.0, 5.0, "minified, between levels 2 and 3"),
    (12.5, 3.0, "anisotropic 4"),
    (64.0, 4.0, "anisotropic 16, the cap"),
    (100.0, 1.0, "anisotropic 100"),
    (400.0, 0.5, "anisotropic 800"),
    (40.0, 40.0, "minified 40"),
    (150.0, 120.0, "minified 150"),
    (1e4, 3e3, "beyond the coarsest level"),
];

/// The disk's probes (kind Disk or Set4) on a w x h texture: every shape
/// at random points and angles, near the edges, sheared, non-finite.
fn disk_probes(kind: Kind, w: u32, h: u32, nm: [f32; 4], rng: &mut Rng) -> Vec<Probe> {
    let (w, h) = (w as f64, h as f64);
    let mut out = Vec::new();
    let mut add = |uv: DVec2, a: DVec2, b: DVec2, what| {
        let t = |v: DVec2| [(v.x / w) as f32, (v.y / h) as f32, 0.0];
        out.push(Probe {
            kind,
            p: [uv.x as f32, uv.y as f32, 0.0],
            dx: t(a),
            dy: t(b),
            nm,
            what,
        });
    };
    for &(s1, s2, what) in &SHAPES {
        for _ in 0..3 {
            let th = rng.next() * std::f64::consts::TAU;
            let e = DVec2::new(th.cos(), th.sin());
            let uv = DVec2::new(rng.next(), rng.next());
            add(uv, e * s1, e.perp() * s2, what);
        }
        // At the edges, where rows and columns clamp.
        let e = DVec2::new(0.8, 0.6);
        add(DVec2::new(0.0005, 0.9995), e * s1, e.perp() * s2, what);
        add(DVec2::new(0.999, 0.002), e.perp() * s2, e * s1, what);
    }
    add(
        DVec2::new(0.41, 0.63),
        DVec2::new(5.0, 1.0),
        DVec2::new(4.5, 1.2),
        "sheared, nearly parallel",
    );
    add(
        DVec2::new(0.5, 0.5),
        DVec2::new(f64::NAN, 1.0),
        DVec2::new(1.0, f64::INFINITY),
        "non-finite footprint",
    );
    out
}

/// The sky's probes (kind Sky or Stars): directions at random, across the
/// seam at u = 0 and next to and at both poles, footprints of a
/// w-texel-wide panorama from magnified to beyond the coarsest level
/// (with a part along the direction, which must not count).
fn sky_probes(kind: Kind, w: u32, rng: &mut Rng) -> Vec<Probe> {
    let texel = std::f64::consts::TAU / w as f64;
    let lat = |deg: f64, phi: f64| {
        let (l, p) = (deg.to_radians(), phi);
        DVec3::new(l.cos() * p.sin(), l.cos() * p.cos(), l.sin())
    };
    let mut dirs: Vec<(DVec3, &'static str)> = (0..6)
        .map(|_| {
            let z = 2.0 * rng.next() - 1.0;
            let phi = rng.next() * std::f64::consts::TAU;
            (lat(z.asin().to_degrees(), phi), "a direction at random")
        })
        .collect();
    dirs.extend([
        (lat(20.0, 1e-4), "across the seam"),
        (lat(-35.0, -1e-4), "across the seam"),
        (lat(10.0, 0.0), "on the seam"),
        (lat(89.5, 1.0), "near the north pole"),
        (lat(89.97, 4.0), "next to the north pole"),
        (DVec3::Z, "at the north pole"),
        (lat(-89.9, 2.5), "near the south pole"),
        (DVec3::new(1e-7, 0.0, -1.0).normalize(), "at the south pole"),
    ]);
    let mut out = Vec::new();
    for (d, what) in dirs {
        let (t1, t2) = frame(d);
        for &(s1, s2, shape) in &SHAPES {
            let th = rng.next() * std::f64::consts::TAU;
            let (a, b) = (t1 * th.cos() + t2 * th.sin(), t2 * th.cos() - t1 * th.sin());
            let (a, b) = (a * s1 * texel + d * 0.3 * texel, b * s2 * texel);
            let what = if what == "a direction at random" {
                shape
            } else {
                what
            };
            out.push(Probe {
                kind,
                p: f3(d),
                dx: f3(a),
                dy: f3(b),
                nm: [0.0; 4],
                what,
            });
        }
    }
    out
}

/// The CPU's value of a probe, from the same f32 inputs (directions
/// normalised in f64, as the CPU takes unit directions).
fn cpu(scene: &Scene, p: &Probe, interp: Interpolation) -> [f64; 4] {
    let v = |a: [f32; 3]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let fp = Footprint {
        dx: v(p.dx).truncate(),
        dy: v(p.dy).truncate(),
    };
    let (u, w) = (p.p[0] as f64, p.p[1] as f64);
    let rgba = |c: glam::Vec4| c.to_array().map(|x| x as f64);
    let material = scene.disk.as_ref().map(|d| &d.material);
    match (p.kind, material, &scene.sky) {
        (Kind::Disk, Some(DiskMaterial::Rgb(t)), _) => rgba(t.sample_footprint(u, w, &fp, false)),
        (Kind::Disk, Some(DiskMaterial::Spectral(s)), _) => {
            let mut texels = Vec::new();
            s.footprint_texels(u, w, &fp, &mut texels);
            [0.0, 0.0, 0.0, s.coverage(&texels) as f64]
        }
        (Kind::Set4, Some(DiskMaterial::Spectral(s)), _) => {
            let mut texels = Vec::new();
            s.footprint_texels(u, w, &fp, &mut texels);
            p.nm.map(|nm| {
                texels
                    .iter()
                    .map(|&(t, wt)| (wt * s.alpha(t) * s.value(t, nm as f64, interp)) as f64)
                    .sum()
            })
        }
        (Kind::Sky, _, Sky::Panorama { texture, .. }) => {
            rgba(texture.sample_sky_footprint(v(p.p).normalize(), v(p.dx), v(p.dy)))
        }
        (Kind::Stars, _, Sky::Stars { map, .. }) => {
            let s = map.sample_footprint(v(p.p).normalize(), v(p.dx), v(p.dy));
            [s.luminance as f64, s.kelvin as f64, s.milky_way as f64, 0.0]
        }
        (Kind::Equirect, _, _) => {
            let (u, w, f) =
                crate::texture::equirect_footprint(v(p.p).normalize(), v(p.dx), v(p.dy));
            [u, w, f.dx.x, f.dy.y]
        }
        _ => panic!("{:?} does not fit this scene", p.kind),
    }
}

/// The probe shader: the scene's, with `tweak` applied (a deliberately
/// wrong kernel), and the probe's entry point.
fn probe_source(pack: &Packed, tweak: &dyn Fn(String) -> String) -> String {
    tweak(pack.shader_source()) + include_str!("../ewa_probe.wgsl")
}

/// Evaluates `probes` on the GPU with `pack` uploaded.
fn run(
    gpu: &Gpu,
    pack: &Packed,
    pipeline: &wgpu::ComputePipeline,
    probes: &[Probe],
) -> Vec<[f32; 4]> {
    let mut words = vec![probes.len() as u32];
    for p in probes {
        words.push(p.kind as u32);
        for x in p.p.iter().chain(&p.dx).chain(&p.dy).chain(&p.nm) {
            words.push(x.to_bits());
        }
        words.extend([0, 0]);
    }
    let storage = wgpu::BufferUsages::STORAGE;
    let buf = |label: &str, bytes: &[u8], usage| gpu.storage(label, bytes, usage).unwrap();
    let params = buf(
        "params",
        bytemuck::bytes_of(&pack.params),
        wgpu::BufferUsages::UNIFORM,
    );
    let tables = buf("tables", bytemuck::cast_slice(&pack.tables), storage);
    let disk = buf("disk", bytemuck::cast_slice(&pack.disk), storage);
    let sky = buf("sky", bytemuck::cast_slice(&pack.sky), storage);
    let inputs = buf("inputs", bytemuck::cast_slice(&words), storage);
    let size = 16 * probes.len() as u64;
    let out = buf(
        "out",
        &vec![0u8; size as usize],
        storage | wgpu::BufferUsages::COPY_SRC,
    );
    let scratch = buf("scratch", &[0u8; 64], storage);
    let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ewa probe"),
        layout: &gpu.layout,
        entries: &[
            (0, &params),
            (1, &tables),
            (2, &disk),
            (3, &sky),
            (4, &out),
            (5, &scratch),
            (6, &scratch),
            (7, &scratch),
            (8, &inputs),
        ]
        .map(|(binding, b)| wgpu::BindGroupEntry {
            binding,
            resource: b.as_entire_binding(),
        }),
    });
    let rb = gpu.readback("ewa probe", size);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups((probes.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &rb, 0, size);
    gpu.queue.submit([enc.finish()]);
    gpu.read::<[f32; 4]>(&rb, size).unwrap()
}

/// Compiles the probe's pipeline.
fn pipeline(gpu: &Gpu, source: &str) -> wgpu::ComputePipeline {
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = gpu
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("ewa probe"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
    let p = gpu
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("ewa_probe"),
            layout: Some(&gpu.pipeline_layout),
            module: &module,
            entry_point: Some("ewa_probe"),
            compilation_options: Default::default(),
            cache: None,
        });
    gpu.settle(scope).unwrap();
    gpu.check().unwrap();
    p
}

/// The worst difference of the GPU's values from the CPU's, each relative
/// to its quantity's size: RGBA and coverage against 1 (their full
/// scale), the set's values against the largest of the probe's four, the
/// stars' luminance, kelvin and Milky Way each against its own value
/// (floored at 1e-3 of the largest in the list). With the worst probe.
fn worst(
    scene: &Scene,
    probes: &[Probe],
    gpu: &[[f32; 4]],
    interp: Interpolation,
) -> (f64, String) {
    let want: Vec<[f64; 4]> = probes.iter().map(|p| cpu(scene, p, interp)).collect();
    let mut floor = [0.0f64; 4];
    for w in &want {
        for k in 0..4 {
            floor[k] = floor[k].max(1e-3 * w[k].abs());
        }
    }
    let mut out = (0.0, String::new());
    for ((p, w), g) in probes.iter().zip(&want).zip(gpu) {
        for k in 0..4 {
            let scale = match p.kind {
                Kind::Disk | Kind::Sky => 1.0,
                Kind::Set4 => w.iter().fold(1e-30f64, |m, x| m.max(x.abs())),
                Kind::Stars => w[k].abs().max(floor[k]).max(1e-30),
                // Texture coordinates in texels of a 512-wide panorama,
                // their derivatives relative to the largest.
                Kind::Equirect if k < 2 => 1.0 / 512.0,
                Kind::Equirect => floor[k] * 1e3,
            };
            let e = (g[k] as f64 - w[k]).abs() / scale;
            // A NaN is the worst difference.
            if !(e <= out.0) {
                out = (
                    if e.is_nan() { f64::INFINITY } else { e },
                    format!("{} ({p:?}): GPU {g:?}, CPU {w:?}", p.what),
                );
            }
        }
    }
    out
}

/// The disk (RGBA texture or spectral set) and sky (panorama or star map)
/// scenes of the test, each with its probes.
fn cases(tmp: &Path) -> Vec<(&'static str, Scene, Vec<Probe>)> {
    let (disk, sky) = write_textures(tmp);
    let q = |p: &Path| format!("\"{}\"", p.display());
    let footprint = [
        "disk.filter=\"footprint\"".to_string(),
        "sky.filter=\"footprint\"".to_string(),
    ];
    let mut sets = footprint.to_vec();
    sets.push(format!("disk.texture={}", q(&disk)));
    sets.push("-sky.stars".into());
    sets.push(format!("sky.texture={}", q(&sky)));
    let rgba = scene("quick", &sets);
    let mut rng = Rng(3);
    let mut probes = disk_probes(Kind::Disk, 300, 212, [0.0; 4], &mut rng);
    probes.extend(sky_probes(Kind::Sky, 360, &mut rng));
    let mut sets = footprint.to_vec();
    sets.push("sky.resolution=512".into());
    let spectral = scene("spectral_side", &sets);
    let (w, h) = match &spectral.disk.as_ref().unwrap().material {
        DiskMaterial::Spectral(s) => (s.width, s.height),
        _ => panic!("spectral_side has a spectral set"),
    };
    let mut set = disk_probes(Kind::Disk, w, h, [0.0; 4], &mut rng);
    for nm in [[195.0, 200.0, 437.3, 1210.0], [555.5, 910.0, 1199.9, 640.0]] {
        set.extend(disk_probes(Kind::Set4, w, h, nm, &mut rng));
    }
    // The star sky as footprint filtering builds it (point stars apart:
    // the Milky Way alone, 128 texels wide), and a map with its star grid.
    set.extend(sky_probes(Kind::Stars, 128, &mut rng));
    let mut grid = scene("spectral_side", &sets);
    if let Sky::Stars { map, points, .. } = &mut grid.sky {
        let csv = std::fs::read_to_string(root().join("spectral_assets/stars/hipparcos_mag8.csv"))
            .unwrap();
        let stars = crate::starmap::parse_catalogue(&csv).unwrap();
        *map = crate::starmap::StarMap::build(&stars, 512, true);
        *points = None;
    }
    let mut stars = sky_probes(Kind::Stars, 512, &mut rng);
    let mut mapping = sky_probes(Kind::Equirect, 512, &mut rng);
    for p in &mut mapping {
        p.kind = Kind::Equirect;
    }
    stars.extend(mapping);
    vec![
        ("RGBA disk and panorama", rgba, probes),
        ("spectral set and Milky Way", spectral, set),
        ("star map with its grid", grid, stars),
    ]
}

#[test]
fn the_probe_shader_validates() {
    // Without a GPU: the probe's entry point and the lookups it calls.
    let tmp = tempfile::tempdir().unwrap();
    let (_, s, _) = cases(tmp.path()).remove(1);
    let source = probe_source(&Packed::new(&s).unwrap(), &|s| s);
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
}

/// The harness tells kernels apart: with the anisotropy capped at 8
/// rather than 16, or a Gaussian of half the falloff, the RGBA lookups
/// differ from the CPU's by far more than [`TOLERANCE`].
fn kernels_that_differ_are_caught(gpu: &Gpu, scene: &Scene, probes: &[Probe]) {
    let pack = Packed::new(scene).unwrap();
    let cap = |s: String| {
        let from = "const EWA_MAX_ANISOTROPY: f32 = 16.0;";
        assert!(s.contains(from));
        s.replace(from, "const EWA_MAX_ANISOTROPY: f32 = 8.0;")
    };
    let got = run(
        gpu,
        &pack,
        &pipeline(gpu, &probe_source(&pack, &cap)),
        probes,
    );
    let (capped, _) = worst(scene, probes, &got, Interpolation::Linear);
    let mut wide = Packed::new(scene).unwrap();
    let at = wide.params.at_ewa_weights as usize;
    for (i, w) in wide.tables[at..at + crate::texture::ewa::TABLE + 2]
        .iter_mut()
        .enumerate()
    {
        let r2 = (i as f64 / crate::texture::ewa::TABLE as f64).min(1.0);
        *w = ((-r2).exp() - (-1.0f64).exp()) as f32;
    }
    let p = pipeline(gpu, &probe_source(&wide, &|s| s));
    let (falloff, _) = worst(
        scene,
        probes,
        &run(gpu, &wide, &p, probes),
        Interpolation::Linear,
    );
    eprintln!("wrong kernels: anisotropy capped at 8 {capped:.2e}, half the falloff {falloff:.2e}");
    assert!(capped > 10.0 * TOLERANCE && falloff > 10.0 * TOLERANCE);
}

/// Most the GPU's lookups may differ from the CPU's (see [`worst`]).
const TOLERANCE: f64 = 1e-4;

#[test]
fn the_wgsl_footprint_lookups_are_the_cpus() {
    let gpu = match Gpu::new() {
        Ok(g) => g,
        Err(e) => {
            assert!(
                std::env::var_os("CI").is_none(),
                "CI installs software Vulkan: {e}"
            );
            eprintln!("skipped: there is no GPU adapter ({e})");
            return;
        }
    };
    let tmp = tempfile::tempdir().unwrap();
    let mut failed = Vec::new();
    let cases = cases(tmp.path());
    kernels_that_differ_are_caught(&gpu, &cases[0].1, &cases[0].2);
    for (name, scene, probes) in cases {
        let mut pack = Packed::new(&scene).unwrap();
        let p = pipeline(&gpu, &probe_source(&pack, &|s| s));
        let interps: &[_] = if scene.spectral.is_some() {
            &[Interpolation::Linear, Interpolation::Nearest]
        } else {
            &[Interpolation::Linear]
        };
        for &interp in interps {
            let linear = super::super::layout::FLAG_LINEAR;
            pack.params.flags &= !linear;
            if interp == Interpolation::Linear {
                pack.params.flags |= linear;
            }
            let got = run(&gpu, &pack, &p, &probes);
            for kind in [
                Kind::Disk,
                Kind::Set4,
                Kind::Sky,
                Kind::Stars,
                Kind::Equirect,
            ] {
                let (probes, got): (Vec<Probe>, Vec<[f32; 4]>) = probes
                    .iter()
                    .zip(&got)
                    .filter(|(p, _)| p.kind == kind)
                    .unzip();
                if probes.is_empty() {
                    continue;
                }
                let (e, at) = worst(&scene, &probes, &got, interp);
                eprintln!(
                    "{name}, {kind:?} ({interp:?}): {} lookups, worst difference {e:.2e}",
                    probes.len()
                );
                if !(e < TOLERANCE) {
                    failed.push(format!("{name} ({interp:?}): {e:.2e} at {at}"));
                }
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
