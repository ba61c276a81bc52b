//! The memory estimate (`blackhole info`'s "memory needed", the check
//! before a render starts) against what renders take. In a test binary of
//! its own: a child's peak memory as the kernel reports it includes the
//! test process's own (see `peak_rss`), which the other tests would swell.

mod common;

use std::io::Write;
use std::process::Command;

fn bin() -> Command {
    common::bin()
}

/// Runs `cmd` and returns (its exit code, stderr, its peak resident memory
/// in bytes), the peak from the kernel's accounting of that one child.
/// The kernel counts in a child's peak the resident memory of the process
/// it was started from (a vfork child shares it until its exec), so these
/// tests live in a test binary of their own that stays small.
fn peak_rss(cmd: &mut Command) -> (Option<i32>, String, u64) {
    use std::io::Read;
    let mut child = cmd
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    // SAFETY: waits for our own child, filling the structs it is given.
    let r = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(r, child.id() as i32);
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    // Reaped above; the handle has nothing left to wait for.
    std::mem::forget(child);
    (code, err, usage.ru_maxrss as u64 * 1024)
}

/// Runs `cmd` under an address-space limit of `bytes`.
fn limit_address_space(cmd: &mut Command, bytes: u64) {
    // SAFETY: setrlimit between fork and exec touches only the child.
    unsafe {
        std::os::unix::process::CommandExt::pre_exec(cmd, move || {
            let lim = libc::rlimit {
                rlim_cur: bytes,
                rlim_max: bytes,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

/// `info`'s estimate of what a render of the scene needs (bytes).
fn estimate(config: &std::path::Path, args: &[&str]) -> u64 {
    let out = bin().arg("info").arg(config).args(args).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with("memory needed"))
        .unwrap_or_else(|| panic!("no memory line: {text}"));
    let mib: f64 = line
        .split_whitespace()
        .nth(2)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    (mib * (1 << 20) as f64) as u64
}

#[test]
fn the_memory_estimate_is_within_twice_the_peak() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A flat mesh of 500,000 triangles, written as it is made (this
    // process stays small: see peak_rss).
    let n = 500;
    let mesh = d.join("grid.obj");
    let mut obj = std::io::BufWriter::new(std::fs::File::create(&mesh).unwrap());
    for j in 0..=n {
        for i in 0..=n {
            writeln!(obj, "v {} {} 0", i as f64 / n as f64, j as f64 / n as f64).unwrap();
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            writeln!(
                obj,
                "f {a} {} {}\nf {a} {} {}",
                a + 1,
                a + n + 2,
                a + n + 2,
                a + n + 1
            )
            .unwrap();
        }
    }
    obj.flush().unwrap();
    drop(obj);
    let root = common::root();
    let cfg = |name: &str| root.join("configs").join(name);
    let png = format!("image.png={}", d.join("x.png").display());
    let exr = format!("image.exr={}", d.join("x.exr").display());
    let mesh_object = format!(
        "object.0={{kind=\"mesh\", file=\"{}\", position=[-3e10,-1.5e11,-1e10], rotation=[90.0,0.0,0.0], scale=4e10, material={{kind=\"color\"}}}}",
        mesh.display()
    );
    let bloom = "bloom={strength=0.1,radius=0.01,spectral=true}";
    let cases: Vec<(&str, Vec<&str>)> = vec![
        // Textures dominate.
        ("quick.toml", vec![]),
        // Spectral bloom's bands dominate.
        (
            "spectral_side.toml",
            vec!["image.width=1024", "image.height=1024", bloom],
        ),
        // Every wavelength in the EXR.
        (
            "spectral_side.toml",
            vec![
                "image.width=512",
                "image.height=512",
                "spectral.exr_layers=true",
            ],
        ),
        // Three films and the composites.
        ("stereo.toml", vec!["image.width=480", "image.height=270"]),
        // A mesh.
        (
            "quick.toml",
            vec!["image.width=64", "image.height=64", &mesh_object],
        ),
        // A large star map.
        (
            "spectral_side.toml",
            vec!["image.width=64", "image.height=36", "sky.resolution=8192"],
        ),
        // RGB bloom and a float EXR with XYZ.
        ("quick.toml", vec![bloom, "image.exr_xyz=true", &exr]),
    ];
    for (name, sets) in cases {
        let mut args: Vec<String> = vec!["--set".into(), png.clone()];
        for s in &sets {
            args.extend(["--set".to_string(), s.to_string()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let est = estimate(&cfg(name), &args);
        let (code, err, peak) = peak_rss(
            bin()
                .arg("render")
                .arg("-q")
                .arg("--overwrite")
                .arg(cfg(name))
                .args(&args),
        );
        assert_eq!(code, Some(0), "{name} {sets:?}: {err}");
        let ratio = est as f64 / peak as f64;
        eprintln!(
            "{name} {sets:?}: estimate {:.0} MiB, peak {:.0} MiB ({ratio:.2})",
            est as f64 / 1048576.0,
            peak as f64 / 1048576.0
        );
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{name} {sets:?}: estimate {est}, peak {peak}"
        );
    }
}

#[test]
fn a_render_beyond_the_memory_limit_is_refused_before_work() {
    // Under a 3 GiB address-space limit: an 8192^2 spectral-bloom render
    // (its film alone 7.5 GiB) and a 65536-texel star map (24 GiB).
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::root().join("configs").join("spectral_side.toml");
    let png = format!("image.png={}", dir.path().join("x.png").display());
    for (sets, needle) in [
        (
            vec![
                "image.width=8192",
                "image.height=8192",
                "bloom={strength=0.1,radius=0.01,spectral=true}",
            ],
            "the film (8192 x 8192)",
        ),
        (
            vec!["sky.resolution=65536", "sky.filter=\"nearest\""],
            "the star map (sky.resolution)",
        ),
    ] {
        let mut cmd = bin();
        cmd.arg("render").arg(&cfg).args(["--set", &png]);
        for s in &sets {
            cmd.args(["--set", s]);
        }
        limit_address_space(&mut cmd, 3 << 30);
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{sets:?}: {err}");
        assert!(
            err.contains("needs about")
                && err.contains(needle)
                && err.contains("address-space limit"),
            "{sets:?}: {err}"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}

#[test]
fn relens_beyond_the_memory_limit_is_refused_before_it_reads() {
    // A 32768 x 16384 panorama (1-bit grey, 2 MB on disk: 2 GiB of texels
    // and their mip levels once read) through a small lens map, under a 3
    // GiB address-space limit: refused by name with the sizes, before
    // anything is decoded (it failed in the decoder's conversion, exit
    // 101); nothing written.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pano = d.join("big.png");
    {
        let file = std::io::BufWriter::new(std::fs::File::create(&pano).unwrap());
        let mut enc = png::Encoder::new(file, 32768, 16384);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::One);
        let mut w = enc.write_header().unwrap().into_stream_writer().unwrap();
        let row = vec![0u8; 32768 / 8];
        for _ in 0..16384 {
            w.write_all(&row).unwrap();
        }
        w.finish().unwrap();
    }
    let cfg = common::root().join("configs").join("quick.toml");
    let exr = d.join("map.exr");
    let out = bin()
        .arg("render")
        .arg(&cfg)
        .args(["-q", "--set", "image.width=16", "--set", "image.height=8"])
        .args([
            "--set",
            &format!("image.png={}", d.join("map.png").display()),
        ])
        .args(["--set", &format!("image.exr={}", exr.display())])
        .args(["--set", "image.observables=[\"sky\"]"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut cmd = bin();
    cmd.arg("relens")
        .arg(&exr)
        .arg(&pano)
        .arg(d.join("out.png"));
    limit_address_space(&mut cmd, 3 << 30);
    let (code, err, peak) = peak_rss(&mut cmd);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("relens needs about")
            && err.contains("the panorama")
            && err.contains("address-space limit"),
        "{err}"
    );
    assert!(
        peak < 200 << 20,
        "{peak} bytes at the peak: the panorama was read"
    );
    assert!(!d.join("out.png").exists());
}
