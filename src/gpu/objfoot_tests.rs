//! The GPU's footprints at object hits (objfoot.wgsl) against the CPU's
//! (`Scene::object_hit` and `Scene::object_footprint`, f64), point by point:
//! a compute entry point of the tests alone (objfoot_probe.wgsl) finds the
//! sample's hit and its footprint as a render does. Without a GPU adapter
//! the GPU part prints why and passes, unless `CI` is set (CI installs
//! software Vulkan); the probe's shader is validated without one.

use super::Gpu;
use super::pack::Packed;
use crate::config::SceneConfig;
use crate::scene::Scene;
use crate::texture::Footprint;
use glam::DVec2;
use std::path::Path;

/// What the GPU found at one point: the object (None: none), and its
/// footprint where it has one.
type Found = Option<(usize, Option<Footprint>)>;

/// A 64 x 48 scene of unit mass (lengths in r_s), the camera at `at`
/// looking at `look` with a 40 degree view, at the GPU's tolerance floor,
/// with `objects` (TOML).
fn scene(model: &str, at: [f64; 3], look: [f64; 3], objects: &str) -> Scene {
    let c: f64 = 2.997_924_58e8;
    let mass = c * c / (2.0 * crate::units::G);
    let v = |a: [f64; 3]| format!("[{:e}, {:e}, {:e}]", a[0], a[1], a[2]);
    let text = format!(
        "[image]\nwidth = 64\nheight = 48\npng = \"unused.png\"\n[camera]\nposition = {}\n\
         look_at = {}\nfov = 40.0\n[black_hole]\nmass = {mass:e}\n[physics]\nmodel = \"{model}\"\n\
         tolerance = {:e}\n[sky]\ncolor = [0.0, 0.0, 0.0]\n{objects}",
        v(at.map(|x| x * crate::scene::schwarzschild_radius(mass))),
        v(look.map(|x| x * crate::scene::schwarzschild_radius(mass))),
        super::MIN_GPU_TOLERANCE,
    );
    let cfg: SceneConfig = toml::from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    Scene::build(cfg).unwrap()
}

/// A textured rectangle read over footprints (lengths in r_s: metres at
/// unit mass).
fn rectangle(c: [f64; 3], n: [f64; 3], w: [f64; 3], size: [f64; 2], tex: &Path) -> String {
    let v = |a: [f64; 3]| format!("[{:e}, {:e}, {:e}]", a[0], a[1], a[2]);
    format!(
        "[[object]]\nkind = \"rectangle\"\ncenter = {}\nnormal = {}\nwidth_axis = {}\n\
         size = [{:e}, {:e}]\nmaterial = {{ kind = \"color\", texture = \"{}\", \
         filter = \"footprint\" }}\n",
        v(c),
        v(n),
        v(w),
        size[0],
        size[1],
        tex.display()
    )
}

/// A small checkerboard PNG.
fn checkerboard(dir: &Path) -> std::path::PathBuf {
    let img = image::RgbImage::from_fn(32, 32, |x, y| {
        let c = if (x / 4 + y / 4).is_multiple_of(2) {
            0
        } else {
            255
        };
        image::Rgb([c, c, c])
    });
    let path = dir.join("checker.png");
    img.save(&path).unwrap();
    path
}

/// The probe's shader for `pack`, with `tweak` applied to it.
fn probe_source(pack: &Packed, tweak: &dyn Fn(String) -> String) -> String {
    tweak(pack.shader_source()) + include_str!("objfoot_probe.wgsl")
}

/// The probe's answers at the image points `at` of the scene `pack` packs.
fn run(gpu: &Gpu, pack: &Packed, source: &str, at: &[DVec2]) -> Vec<Found> {
    let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = gpu
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("objfp probe"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
    let pipeline = gpu
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("objfp_probe"),
            layout: Some(&gpu.pipeline_layout),
            module: &module,
            entry_point: Some("objfp_probe"),
            compilation_options: Default::default(),
            cache: None,
        });
    gpu.settle(scope).unwrap();
    gpu.check().unwrap();
    let n = at.len();
    let mut film = vec![[0.0f32; 4]; 1 + 3 * n];
    film[0][0] = f32::from_bits(n as u32);
    for (k, p) in at.iter().enumerate() {
        film[1 + k] = [p.x as f32, p.y as f32, 0.0, 0.0];
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
    let objects = buf("objects", bytemuck::cast_slice(&pack.objects), storage);
    let size = 16 * film.len() as u64;
    let out = buf(
        "film",
        bytemuck::cast_slice(&film),
        storage | wgpu::BufferUsages::COPY_SRC,
    );
    let scratch = buf("scratch", &[0u8; 64], storage);
    let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("objfp probe"),
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
            (8, &objects),
        ]
        .map(|(binding, b)| wgpu::BindGroupEntry {
            binding,
            resource: b.as_entire_binding(),
        }),
    });
    let rb = gpu.readback("objfp probe", size);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups((n as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &rb, 0, size);
    gpu.queue.submit([enc.finish()]);
    let got = gpu.read::<[f32; 4]>(&rb, size).unwrap();
    (0..n)
        .map(|k| {
            let (a, b) = (got[1 + n + 2 * k], got[2 + n + 2 * k]);
            (a[0] >= 0.0).then(|| {
                let fp = (a[1] > 0.0)
                    .then(|| Footprint::new(b[0] as f64, b[1] as f64, b[2] as f64, b[3] as f64));
                (a[0] as usize, fp)
            })
        })
        .collect()
}

/// The CPU's answer at `at`.
fn cpu(s: &Scene, at: DVec2) -> Found {
    let (i, hit, plane) = s.object_hit(at)?;
    Some((i, s.object_footprint(at, i, &hit, plane)))
}

/// The size of a footprint (its Jacobian's Frobenius norm).
fn norm(f: &Footprint) -> f64 {
    (f.dx.length_squared() + f.dy.length_squared()).sqrt()
}

/// The median and worst difference of the GPU's footprints from the CPU's
/// relative to the CPU's size, over points where both have one; panics
/// where they disagree on the object or on whether there is a footprint.
fn worst(name: &str, s: &Scene, at: &[DVec2], gpu: &[Found]) -> (f64, f64) {
    let mut all = Vec::new();
    for (p, g) in at.iter().zip(gpu) {
        let c = cpu(s, *p);
        match (c, g) {
            (None, None) => {}
            (Some((i, Some(a))), Some((j, Some(b)))) if i == *j => {
                all.push((a.dx - b.dx).length().max((a.dy - b.dy).length()) / norm(&a));
            }
            (Some((i, None)), Some((j, None))) if i == *j => {}
            _ => panic!("{name} at {p}: CPU {c:?}, GPU {g:?}"),
        }
    }
    all.sort_by(f64::total_cmp);
    (all[all.len() / 2], all[all.len() - 1])
}

/// The cases: (name, scene, image points).
fn cases(tex: &Path) -> Vec<(&'static str, Scene, Vec<DVec2>)> {
    let mut out = Vec::new();
    // Nearly flat space, 1000 r_s out looking away: a rectangle 100 r_s
    // ahead facing the camera, in both models.
    let grid: Vec<DVec2> = (0..24)
        .map(|k| DVec2::new(3.3 + 2.61 * k as f64, 2.7 + 1.87 * k as f64))
        .collect();
    for model in ["gr", "seed"] {
        let rect = rectangle(
            [0.0, -1100.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [120.0, 90.0],
            tex,
        );
        let s = scene(model, [0.0, -1000.0, 0.0], [0.0, -2000.0, 0.0], &rect);
        out.push((
            if model == "gr" {
                "straight-on rectangle, gr"
            } else {
                "straight-on rectangle, seed"
            },
            s,
            grid.clone(),
        ));
    }
    // A sphere 6 r_s behind the hole seen lensed from 20 r_s.
    let ball = format!(
        "[[object]]\nkind = \"sphere\"\ncenter = [2.5, 6.0, 1.0]\nradius = 2.0\n\
         material = {{ kind = \"color\", texture = \"{}\", filter = \"footprint\" }}\n",
        tex.display()
    );
    let s = scene("gr", [0.0, -20.0, 0.0], [0.0; 3], &ball);
    let pts: Vec<DVec2> = (0..400)
        .map(|k| DVec2::new(0.37 + (k % 20) as f64 * 3.2, 0.61 + (k / 20) as f64 * 2.4))
        .filter(|p| s.object_hit(*p).is_some())
        .collect();
    out.push(("lensed sphere, gr", s, pts));
    // A rectangle 100 r_s ahead in front of a wider one 200 r_s ahead,
    // their widths turned apart; samples ever closer to the front one's
    // right edge on both sides.
    let front = rectangle(
        [0.0, -1100.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [40.0, 30.0],
        tex,
    );
    let back = rectangle(
        [0.0, -1200.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [300.0, 400.0],
        tex,
    );
    let s = scene(
        "gr",
        [0.0, -1000.0, 0.0],
        [0.0, -2000.0, 0.0],
        &(front + &back),
    );
    let unit = 2.0 * 20f64.to_radians().tan() / 48.0;
    let edge = 32.0 + 20.0 / (100.0 * unit);
    let pts = (-20..=20)
        .flat_map(|k| [20.3, 24.0, 27.9].map(|y| DVec2::new(edge + k as f64 * 0.01, y)))
        .collect();
    out.push(("across a silhouette", s, pts));
    out
}

#[test]
fn the_probe_shader_validates() {
    let tmp = tempfile::tempdir().unwrap();
    let (_, s, _) = cases(&checkerboard(tmp.path())).remove(2);
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

/// Most the GPU's footprints may differ from the CPU's, relative to their
/// size (f32's rounding over the step; see OBJ_STEP in objfoot.wgsl).
const TOLERANCE: f64 = 1e-2;

#[test]
fn the_gpu_footprints_at_object_hits_are_the_cpus() {
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
    let tex = checkerboard(tmp.path());
    // OBJFP_STEPS=1: the steps the default was chosen from, each measured.
    let steps: &[f32] = if std::env::var_os("OBJFP_STEPS").is_some() {
        &[1.0 / 256.0, 1.0 / 128.0, 1.0 / 64.0, 1.0 / 32.0, 1.0 / 16.0]
    } else {
        &[1.0 / 128.0]
    };
    let mut failed = Vec::new();
    for (name, s, at) in cases(&tex) {
        let pack = Packed::new(&s).unwrap();
        for &step in steps {
            let tweak = |src: String| {
                let from = "const OBJ_STEP: f32 = 0.0078125;";
                assert!(src.contains(from));
                src.replace(from, &format!("const OBJ_STEP: f32 = {step:?};"))
            };
            let got = run(&gpu, &pack, &probe_source(&pack, &tweak), &at);
            let with = got
                .iter()
                .filter(|g| g.is_some_and(|g| g.1.is_some()))
                .count();
            let (median, e) = worst(name, &s, &at, &got);
            eprintln!(
                "{name}: step {step} px, {with} of {} points with footprints, relative \
                 difference median {median:.1e}, worst {e:.1e}",
                at.len()
            );
            if step == 1.0 / 128.0 && !(e < TOLERANCE) {
                failed.push(format!("{name}: {e:.2e}"));
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
