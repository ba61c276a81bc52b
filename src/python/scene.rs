//! Scenes: loaded with the command line's overrides, rendered on a thread
//! of their own while the caller waits without the GIL, listening for
//! Ctrl-C.

use super::image::Image;
use super::{BlackholeError, error, to_table, to_toml};
use crate::config::{Override, SceneConfig};
use crate::memory::Job;
use crate::pipeline::{Backend, BackendKind, check_memory};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// A scene, built and checked: every asset loaded, nothing rendered.
#[pyclass(frozen, module = "blackhole._native", name = "Scene")]
pub struct PyScene {
    scene: Arc<crate::scene::Scene>,
}

/// `set` (dict: dotted key -> value) and `unset` (a key or keys) as the
/// command line's `--unset` then `--set`.
fn overrides(
    set: Option<&Bound<'_, PyDict>>,
    unset: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<Override>> {
    let mut out = Vec::new();
    let unset: Vec<String> = match unset {
        None => Vec::new(),
        Some(u) if u.is_instance_of::<PyString>() => vec![u.extract()?],
        Some(u) => u.extract().map_err(|_| {
            BlackholeError::new_err("unset: expected a key or a list of keys (str)")
        })?,
    };
    for key in unset {
        out.push(Override::unset(&key).map_err(error)?);
    }
    if let Some(set) = set {
        for (k, v) in set.iter() {
            let key: String = k
                .cast::<PyString>()
                .map_err(|_| BlackholeError::new_err(format!("set: the key {k} is not a string")))?
                .extract()?;
            let value = to_toml(&v, &format!("set[{key:?}]"))?;
            out.push(Override::try_value(&key, value).map_err(error)?);
        }
    }
    Ok(out)
}

fn build(config: SceneConfig, name: &Path) -> PyResult<PyScene> {
    let scene = crate::scene::Scene::build(config).map_err(|e| {
        error(anyhow::Error::new(e).context(format!("invalid scene {}", name.display())))
    })?;
    Ok(PyScene {
        scene: Arc::new(scene),
    })
}

/// Loads the scene file `path` with `set` and `unset` applied as
/// `--set`/`--unset`; its relative paths are against its folder, those of
/// `set` against the current one.
#[pyfunction]
#[pyo3(signature = (path, set=None, unset=None))]
fn load(
    path: PathBuf,
    set: Option<&Bound<'_, PyDict>>,
    unset: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyScene> {
    let overrides = overrides(set, unset)?;
    let config = SceneConfig::load(&path, &overrides).map_err(error)?;
    build(config, &path)
}

/// A scene from TOML text or a dict, its relative paths against `base`
/// (the current folder by default).
#[pyfunction]
#[pyo3(signature = (scene, base=None, set=None, unset=None))]
fn loads(
    scene: &Bound<'_, PyAny>,
    base: Option<PathBuf>,
    set: Option<&Bound<'_, PyDict>>,
    unset: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyScene> {
    let text = if let Ok(s) = scene.cast::<PyString>() {
        s.extract::<String>()?
    } else if let Ok(d) = scene.cast::<PyDict>() {
        toml::to_string(&to_table(d, "")?).map_err(|e| {
            BlackholeError::new_err(format!("the dict cannot be written as TOML: {e}"))
        })?
    } else {
        return Err(BlackholeError::new_err(format!(
            "loads takes TOML text or a dict, not a {}",
            scene.get_type().name()?
        )));
    };
    let cwd = std::env::current_dir().unwrap_or_default();
    let base = match base {
        Some(b) if b.is_absolute() => b,
        Some(b) => cwd.join(b),
        None => cwd,
    };
    if !base.is_dir() {
        return Err(BlackholeError::new_err(format!(
            "base {}: expected a folder (the scene's relative paths start there)",
            base.display()
        )));
    }
    let name = base.join("<string>");
    let overrides = overrides(set, unset)?;
    let config = SceneConfig::from_text(&text, &name, &overrides).map_err(error)?;
    build(config, &name)
}

/// The GPU device, opened by the first GPU render and kept for the
/// process: later renders reuse it and its compiled shaders.
static GPU: std::sync::Mutex<Option<Arc<crate::gpu::Gpu>>> = std::sync::Mutex::new(None);

/// The process's GPU device, opened if it is not yet.
fn gpu() -> anyhow::Result<Arc<crate::gpu::Gpu>> {
    let mut held = GPU.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(g) = held.as_ref() {
        return Ok(g.clone());
    }
    let g = Arc::new(crate::gpu::Gpu::new()?);
    *held = Some(g.clone());
    Ok(g)
}

/// Forgets the process's GPU device (after an error: the next render opens
/// a new one rather than a lost one).
fn forget_gpu() {
    *GPU.lock().unwrap_or_else(|e| e.into_inner()) = None;
}

/// Where a render stands, shared with its thread.
struct Progress {
    rows: AtomicU64,
    stop: Arc<AtomicBool>,
}

/// Held by a GPU render: renders on the kept device take turns (its error
/// sink is the device's, not the render's).
static GPU_TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// `render`'s `backend`: "cpu" or "gpu".
fn backend_kind(backend: &str) -> PyResult<BackendKind> {
    match backend {
        "cpu" => Ok(BackendKind::Cpu),
        "gpu" => Ok(BackendKind::Gpu),
        other => Err(BlackholeError::new_err(format!(
            "backend {other:?}: expected \"cpu\" or \"gpu\""
        ))),
    }
}

/// `render`'s `threads`: 1 to 4096 workers, or None for one per core.
fn worker_count(threads: Option<i64>) -> PyResult<Option<usize>> {
    if let Some(n) = threads
        && !(1..=4096).contains(&n)
    {
        return Err(BlackholeError::new_err(format!(
            "threads {n}: expected 1 to 4096 workers, or None for one per core"
        )));
    }
    Ok(threads.map(|n| n as usize))
}

/// `render`'s `tile` (i, n) as the rows of tile i of n of an image `h`
/// rows high; None renders them all.
fn tile_rows(tile: Option<&[i64]>, h: u32) -> PyResult<Option<Range<u32>>> {
    match tile {
        None => Ok(None),
        Some(&[i, n]) => {
            let (Ok(i), Ok(n)) = (u32::try_from(i), u32::try_from(n)) else {
                return Err(BlackholeError::new_err(format!(
                    "tile ({i}, {n}): expected (i, n) with 0 <= i < n"
                )));
            };
            crate::tiles::check_tile(i, n, h).map_err(error)?;
            Ok(Some(crate::tiles::tile_rows(h, i, n)))
        }
        Some(other) => Err(BlackholeError::new_err(format!(
            "tile {other:?}: expected (i, n), tile i of n"
        ))),
    }
}

/// The render thread's work: `rows` of `scene` (all if None) on `threads`
/// workers (None: rayon's pool); None if it was stopped.
fn render_thread(
    kind: BackendKind,
    threads: Option<usize>,
    scene: &crate::scene::Scene,
    state: &Progress,
    rows: Option<Range<u32>>,
) -> anyhow::Result<Option<Image>> {
    let out = on_threads(threads, || render_rows(kind, scene, state, rows));
    // A lost or failing device is opened anew next time.
    if let Err(e) = &out
        && matches!(
            e.downcast_ref::<crate::gpu::GpuError>(),
            Some(crate::gpu::GpuError::DeviceLost(_) | crate::gpu::GpuError::Device(_))
        )
    {
        forget_gpu();
    }
    out
}

/// `run` on `threads` workers (None: rayon's pool).
fn on_threads<T>(
    threads: Option<usize>,
    run: impl FnOnce() -> anyhow::Result<T> + Send,
) -> anyhow::Result<T>
where
    T: Send,
{
    match threads {
        None => run(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(anyhow::Error::from)
            .and_then(|pool| pool.install(run)),
    }
}

/// Opens the backend and renders `rows` (all if None), counting finished
/// rows in `state`; None if `state.stop` stopped it.
fn render_rows(
    kind: BackendKind,
    scene: &crate::scene::Scene,
    state: &Progress,
    rows: Option<Range<u32>>,
) -> anyhow::Result<Option<Image>> {
    let _turn =
        (kind == BackendKind::Gpu).then(|| GPU_TURN.lock().unwrap_or_else(|e| e.into_inner()));
    let backend = match kind {
        BackendKind::Cpu => Backend::open(kind, scene)?,
        BackendKind::Gpu => Backend::on_gpu(gpu()?, scene)?,
    };
    let mut prepared = backend.prepare(scene)?;
    // With medium.flux, the mass unit is fitted first (one whole render a
    // try), as the command line's render does.
    let fitted;
    let scene = match scene.flux_target() {
        Some(_) if rows.is_some() => anyhow::bail!(
            "tile with medium.flux: a tile cannot fit the whole image's flux; render the whole image (or call fit_m_unit()) first"
        ),
        Some(_) => {
            let mut s = scene.clone();
            let stop = state.stop.clone();
            let fit = s.fit_m_unit(
                |s| match prepared.render_until(s, None, &|_| {}, &stop)? {
                    Some((film, _)) => Ok(film.total_flux()[0]),
                    None => anyhow::bail!("the render was stopped"),
                },
                |_| {},
            );
            if state.stop.load(Ordering::Relaxed) {
                return Ok(None);
            }
            fit?;
            fitted = s;
            &fitted
        }
        None => scene,
    };
    let start = Instant::now();
    let tick = |n: u64| {
        state.rows.fetch_add(n, Ordering::Relaxed);
    };
    let Some((film, stats)) = prepared.render_until(scene, rows.clone(), &tick, &state.stop)?
    else {
        return Ok(None);
    };
    let seconds = start.elapsed().as_secs_f64();
    Ok(Some(Image::new(
        scene,
        film,
        stats,
        (seconds, prepared.device_seconds()),
        backend.label(),
        rows.unwrap_or(0..scene.camera.height),
    )))
}

/// Waits without the GIL for the render thread's result on `rx`, calling
/// `progress(done, total)` as rows finish and checking for Ctrl-C between
/// waits of 50 ms.
fn wait(
    py: Python<'_>,
    worker: std::thread::JoinHandle<()>,
    rx: std::sync::mpsc::Receiver<anyhow::Result<Option<Image>>>,
    state: &Progress,
    progress: Option<&Py<PyAny>>,
    total: u64,
) -> PyResult<Image> {
    let mut told = 0;
    // In a mutex to cross into the GIL-free wait (it is not Sync).
    let rx = std::sync::Mutex::new(rx);
    loop {
        let got = py.detach(|| {
            let rx = rx.lock().unwrap_or_else(|e| e.into_inner());
            rx.recv_timeout(Duration::from_millis(50))
        });
        match got {
            Ok(out) => {
                let _ = worker.join();
                let image = out
                    .map_err(error)?
                    .ok_or_else(|| BlackholeError::new_err("the render was stopped"))?;
                // The last call tells the render is whole.
                if let Some(cb) = progress
                    && told != total
                {
                    cb.call1(py, (total, total))?;
                }
                return Ok(image);
            }
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(BlackholeError::new_err(
                    "the render thread ended without a result",
                ));
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
        }
        let outcome = py.check_signals().and_then(|()| {
            let done = state.rows.load(Ordering::Relaxed);
            match progress {
                Some(cb) if done != told => {
                    told = done;
                    cb.call1(py, (done, total)).map(|_| ())
                }
                _ => Ok(()),
            }
        });
        if let Err(e) = outcome {
            // Ctrl-C, or the callback raised: the render stops at its
            // next pixel (CPU) or band of rows (GPU) and is waited
            // for. Nothing was written.
            state.stop.store(true, Ordering::Relaxed);
            let _ = py.detach(move || worker.join());
            return Err(e);
        }
    }
}

#[pymethods]
impl PyScene {
    /// Renders the scene: `backend` "cpu" or "gpu"; `threads` workers on
    /// the CPU (None: one per core; the pixels do not depend on it);
    /// `time` the animation's instant in seconds (as `--time`); `tile`
    /// (i, n) renders only the rows of tile i of n (as `--tile i/n`);
    /// `progress(done_rows, total_rows)` is called as rows finish (at
    /// most every 50 ms, and once at the end); an exception it raises
    /// stops the render and is raised.
    #[pyo3(signature = (backend="cpu", threads=None, time=None, tile=None, progress=None))]
    fn render(
        &self,
        py: Python<'_>,
        backend: &str,
        threads: Option<i64>,
        time: Option<f64>,
        tile: Option<Vec<i64>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Image> {
        let kind = backend_kind(backend)?;
        let threads = worker_count(threads)?;
        let scene = match time {
            None => self.scene.clone(),
            Some(t) => {
                let mut s = (*self.scene).clone();
                s.set_time(t).map_err(error)?;
                Arc::new(s)
            }
        };
        let h = scene.camera.height;
        let rows = tile_rows(tile.as_deref(), h)?;
        let job = Job {
            rows: rows.as_ref().map_or(h, |r| r.len() as u32),
            films: 1,
            outputs: rows.is_none(),
            gpu: kind == BackendKind::Gpu,
        };
        check_memory(&scene.config, job, "the render").map_err(error)?;
        let total = rows.as_ref().map_or(h, |r| r.len() as u32) as u64;
        let state = Arc::new(Progress {
            rows: AtomicU64::new(0),
            stop: Arc::new(AtomicBool::new(false)),
        });
        let (tx, rx) = std::sync::mpsc::channel();
        let worker = {
            let (scene, state, rows) = (scene.clone(), state.clone(), rows.clone());
            std::thread::Builder::new()
                .name("blackhole render".into())
                .spawn(move || {
                    let out = render_thread(kind, threads, &scene, &state, rows);
                    let _ = tx.send(out);
                })
                .map_err(|e| error(anyhow::anyhow!("cannot start the render thread: {e}")))?
        };
        wait(py, worker, rx, &state, progress.as_ref(), total)
    }

    /// With `[medium] kind = "grmhd"`: fits the mass unit so that the
    /// total flux density at the first frequency is `flux` Jy (default
    /// `medium.flux`), one CPU render a try, `threads` workers. Gives
    /// {"m_unit", "jy", "slope" (d ln F / d ln m_unit), "tries" [(m_unit,
    /// jy)...], "scene" (the scene at the fitted unit)}.
    #[pyo3(signature = (flux=None, threads=None))]
    fn fit_m_unit<'py>(
        &self,
        py: Python<'py>,
        flux: Option<f64>,
        threads: Option<i64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let threads = worker_count(threads)?;
        let mut scene = (*self.scene).clone();
        let Some(g) = scene.grmhd_mut() else {
            return Err(BlackholeError::new_err(
                "fit_m_unit: the scene has no [medium] kind = \"grmhd\"",
            ));
        };
        if let Some(f) = flux {
            if !(f.is_finite() && f > 0.0) {
                return Err(BlackholeError::new_err(format!(
                    "flux {f}: expected a positive flux density in Jy"
                )));
            }
            g.settings.flux = Some(f);
        }
        if g.settings.flux.is_none() {
            return Err(BlackholeError::new_err(
                "fit_m_unit: no flux to fit: pass flux=... (Jy) or set medium.flux",
            ));
        }
        let fit = py
            .detach(|| {
                on_threads(threads, || {
                    scene.fit_m_unit(|s| Ok(s.render(&|_| {}).0.total_flux()[0]), |_| {})
                })
            })
            .map_err(error)?
            .expect("a flux target");
        let d = PyDict::new(py);
        d.set_item("m_unit", fit.m_unit)?;
        d.set_item("jy", fit.jy)?;
        d.set_item("slope", fit.slope)?;
        let tries: Vec<(f64, f64)> = fit.tries.iter().map(|t| (t.m_unit, t.jy)).collect();
        d.set_item("tries", tries)?;
        d.set_item(
            "scene",
            PyScene {
                scene: Arc::new(scene),
            },
        )?;
        Ok(d)
    }

    /// With `[medium] kind = "grmhd"`: the plasma as the renderer sees it
    /// at Boyer-Lindquist radii `r` (M) and polar angles `theta` and
    /// Kerr-Schild azimuths `phi` (rad, lists of one length), before the
    /// cuts: {"n_e" (cm^-3), "theta_e", "b" (G), "sigma", "u" (u^mu,
    /// Kerr-Schild t, r, theta, phi), "b_mu" (b^mu, G), "native" (X1, X2,
    /// X3)}, NaN outside the grid; and "cm_per_m", "accretion_rate" (g/s).
    fn plasma<'py>(
        &self,
        py: Python<'py>,
        r: Vec<f64>,
        theta: Vec<f64>,
        phi: Vec<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let Some(crate::transfer::Medium::Grmhd(g)) =
            self.scene.observe.as_ref().and_then(|o| o.medium.as_ref())
        else {
            return Err(BlackholeError::new_err(
                "plasma: the scene has no [medium] kind = \"grmhd\"",
            ));
        };
        if r.len() != theta.len() || r.len() != phi.len() {
            return Err(BlackholeError::new_err(
                "plasma: r, theta and phi must be as long as one another",
            ));
        }
        let nan = f64::NAN;
        let probes: Vec<_> = (0..r.len())
            .map(|i| g.probe(r[i], theta[i], phi[i]))
            .collect();
        let d = PyDict::new(py);
        let col = |f: &dyn Fn(&crate::transfer::grmhd::Probe) -> f64| -> Vec<f64> {
            probes.iter().map(|p| p.as_ref().map_or(nan, f)).collect()
        };
        d.set_item("n_e", col(&|p| p.n_e))?;
        d.set_item("theta_e", col(&|p| p.theta_e))?;
        d.set_item("b", col(&|p| p.b_gauss))?;
        d.set_item("sigma", col(&|p| p.sigma))?;
        let vec4 = |f: &dyn Fn(&crate::transfer::grmhd::Probe) -> [f64; 4]| -> Vec<[f64; 4]> {
            probes
                .iter()
                .map(|p| p.as_ref().map_or([nan; 4], f))
                .collect()
        };
        d.set_item("u", vec4(&|p| p.u))?;
        d.set_item("b_mu", vec4(&|p| p.b))?;
        let native: Vec<[f64; 3]> = probes
            .iter()
            .map(|p| p.as_ref().map_or([nan; 3], |p| p.native))
            .collect();
        d.set_item("native", native)?;
        d.set_item("cm_per_m", g.cm_per_m())?;
        d.set_item("accretion_rate", g.accretion_rate())?;
        Ok(d)
    }

    /// What `blackhole info` prints, as {quantity: value with units}.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in crate::info::facts(&self.scene) {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The scene's warnings (settings that do nothing...), one a line.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene.warnings.clone()
    }

    /// (width, height) in pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.scene.camera.width, self.scene.camera.height)
    }

    /// The observables the scene asks for (`image.observables`).
    #[getter]
    fn observables(&self) -> Vec<&'static str> {
        self.scene.observables.iter().map(|o| o.name()).collect()
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.size();
        format!(
            "<blackhole.Scene {w}x{h}, {}, {}>",
            self.scene.model.spacetime().map_or("seed", |s| s.name()),
            if self.scene.spectral.is_some() {
                "spectral"
            } else {
                "rgb"
            }
        )
    }
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(loads, m)?)?;
    Ok(())
}
