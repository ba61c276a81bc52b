//! iharm3d-format GRMHD dumps ("iharm v1", as iharm3d and KHARMA's
//! converter write them and ipole's `model/iharm` reads them): the header,
//! the native grid, and the primitives per cell, read and written through
//! a pure-Rust HDF5 library (no C library to install). A dump that is not
//! what it claims is refused naming the file and the dataset.

use super::coords::Theta;
use hdf5_pure::{File, FileBuilder};
use std::path::{Path, PathBuf};

/// The primitives' columns: density, internal energy, the velocity
/// relative to the normal observer (U1-U3, native components), the field
/// B^i = b^i u^t - b^t u^i (native, Lorentz-Heaviside code units), and
/// where the dump has electrons their entropy (KEL) and the total (KTOT).
pub const RHO: usize = 0;
pub const UU: usize = 1;
pub const U1: usize = 2;
pub const B1: usize = 5;
pub const KEL: usize = 8;
const NAMES: [&str; 10] = [
    "RHO", "UU", "U1", "U2", "U3", "B1", "B2", "B3", "KEL", "KTOT",
];

/// What a dump's header says.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// `/header/metric` as written ("MKS", "FMKS", "MMKS", "BHAC_MKS", "EKS").
    pub metric: String,
    /// Cells along X1, X2, X3.
    pub n: [usize; 3],
    /// The fluid's adiabatic index, and the electrons' and ions' (4/3 and
    /// 5/3 unless the dump says otherwise).
    pub gam: f64,
    pub gam_e: f64,
    pub gam_p: f64,
    /// Columns of `/prims`.
    pub n_prim: usize,
    /// The native grid's first corner and cell widths.
    pub start: [f64; 3],
    pub dx: [f64; 3],
    /// The hole's spin.
    pub a: f64,
    /// The grid's inner and outer radii (M).
    pub r_in: f64,
    pub r_out: f64,
    pub theta: Theta,
    /// The dump's time (M) and the cadence of its series.
    pub t: f64,
    pub dump_cadence: f64,
    /// Whether column KEL holds the electrons' entropy.
    pub has_electrons: bool,
}

/// A dump: its header and its primitives, `n_prim` per cell, X3 fastest.
pub struct Dump {
    pub path: PathBuf,
    pub header: Header,
    pub prims: Prims,
}

/// Where a dump's primitives are: in memory (a torus built here), or in
/// its file, read a few radial rows at a time ([`Dump::rows`]) so that
/// the whole array is never held (a 288x128x128 dump's is 302 MB).
pub enum Prims {
    Memory(Vec<f64>),
    File(hdf5_pure::Dataset),
}

/// Radial rows of primitives read from a file at once.
const ROWS_AT_ONCE: usize = 4;

/// glibc hands the top of its heap back to the system whenever a block
/// freed there leaves more than its threshold free, a threshold it raises
/// only as larger blocks come and go: reading a dump a window at a time
/// (the file's bytes and their values, blocks of a few MB each, freed
/// before the next) faulted in fresh pages for every window, 600 MB for a
/// 302 MB dump, 0.4 s of system time. Reading, the thresholds are set to
/// the most glibc's own would reach (32 MB for a block of its own pages,
/// twice that to keep free at the top); after it, what is spare is handed
/// back.
struct SpareTop;

impl SpareTop {
    fn keep() -> SpareTop {
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: mallopt only sets parameters of the allocator.
        unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
            libc::mallopt(libc::M_TRIM_THRESHOLD, 64 << 20);
        }
        SpareTop
    }
}

impl Drop for SpareTop {
    fn drop(&mut self) {
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: malloc_trim only returns free memory to the system.
        unsafe {
            libc::malloc_trim(0);
        }
    }
}

impl std::fmt::Debug for Dump {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dump")
            .field("path", &self.path)
            .field("header", &self.header)
            .finish_non_exhaustive()
    }
}

/// Why a dump was refused: the file, the dataset and what was wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("GRMHD dump {}: {what}", path.display())]
pub struct DumpError {
    pub path: PathBuf,
    pub what: String,
}

struct Reader<'a> {
    file: File,
    path: &'a Path,
}

impl Reader<'_> {
    fn fail(&self, what: String) -> DumpError {
        DumpError {
            path: self.path.to_path_buf(),
            what,
        }
    }

    fn has(&self, name: &str) -> bool {
        self.file.dataset(name).is_ok()
    }

    fn dataset(&self, name: &str) -> Result<hdf5_pure::Dataset, DumpError> {
        self.file
            .dataset(name)
            .map_err(|e| self.fail(format!("dataset {name}: missing ({e})")))
    }

    fn scalar(&self, name: &str) -> Result<f64, DumpError> {
        let v = self
            .dataset(name)?
            .read_f64()
            .map_err(|e| self.fail(format!("dataset {name}: not a number ({e})")))?;
        match v.as_slice() {
            [x] if x.is_finite() => Ok(*x),
            [x] => Err(self.fail(format!("dataset {name}: {x}, expected a finite number"))),
            _ => Err(self.fail(format!("dataset {name}: {} values, expected one", v.len()))),
        }
    }

    /// The first dataset of `names` that exists, as a number.
    fn either(&self, names: &[&str]) -> Result<f64, DumpError> {
        match names.iter().find(|n| self.has(n)) {
            Some(n) => self.scalar(n),
            None => Err(self.fail(
                format!("dataset {}: missing", names.join(" (or ")) + &")".repeat(names.len() - 1),
            )),
        }
    }

    fn count(&self, name: &str) -> Result<usize, DumpError> {
        let x = self.scalar(name)?;
        if x.fract() != 0.0 || !(1.0..=1e6).contains(&x) {
            return Err(self.fail(format!(
                "dataset {name}: {x}, expected a whole number from 1 to 10^6"
            )));
        }
        Ok(x as usize)
    }

    fn string(&self, name: &str) -> Result<String, DumpError> {
        let v = self
            .dataset(name)?
            .read_string()
            .map_err(|e| self.fail(format!("dataset {name}: not a string ({e})")))?;
        match v.as_slice() {
            [s] => Ok(s.trim_end_matches(['\0', ' ']).to_string()),
            _ => Err(self.fail(format!("dataset {name}: {} strings, expected one", v.len()))),
        }
    }
}

impl Dump {
    /// Reads and checks the dump at `path`.
    pub fn read(path: &Path) -> Result<Dump, DumpError> {
        if !path.exists() {
            return Err(DumpError {
                path: path.to_path_buf(),
                what: "no such file (`blackhole torus FILE` writes the standard torus; medium.torus builds it in memory)".into(),
            });
        }
        let file = File::open_streaming(path).map_err(|e| DumpError {
            path: path.to_path_buf(),
            what: format!("not a readable HDF5 file ({e})"),
        })?;
        let r = Reader { file, path };
        if r.file
            .root()
            .attrs()
            .is_ok_and(|a| a.contains_key("dscale"))
        {
            return Err(
                r.fail("a HAMR dump (root attribute dscale): expected the iharm3d format".into())
            );
        }
        if r.has("/header/version") && r.string("/header/version")? == "KORALv2" {
            return Err(r.fail(
                "dataset /header/version: KORALv2, expected the iharm3d format (a KORAL dump)"
                    .into(),
            ));
        }
        let header = read_header(&r)?;
        let prims = prims_dataset(&r, &header)?;
        Ok(Dump {
            path: path.to_path_buf(),
            header,
            prims: Prims::File(prims),
        })
    }

    /// Hands each radial row of primitives in turn, checked, to `each`:
    /// its index i and its cells' primitives ([n2][n3][n_prim]). A dump
    /// with NaN cells, negative RHO or UU, or a row its file cannot give
    /// is refused by name (after the rows before it were handed on).
    pub fn rows(&self, mut each: impl FnMut(usize, &[f64])) -> Result<(), DumpError> {
        let h = &self.header;
        let fail = |what: String| DumpError {
            path: self.path.clone(),
            what,
        };
        let row = h.n[1] * h.n[2] * h.n_prim;
        let mut negative = 0;
        let mut check = |i0: usize, rows: &[f64]| -> Result<(), DumpError> {
            if let Some(at) = rows.iter().position(|x| !x.is_finite()) {
                let cell = at / h.n_prim;
                let (i, j, k) = (
                    i0 + cell / (h.n[1] * h.n[2]),
                    (cell / h.n[2]) % h.n[1],
                    cell % h.n[2],
                );
                return Err(fail(format!(
                    "dataset /prims: {} at cell ({i}, {j}, {k}), column {}: expected finite values",
                    rows[at],
                    NAMES.get(at % h.n_prim).copied().unwrap_or("?")
                )));
            }
            negative += rows
                .chunks_exact(h.n_prim)
                .filter(|p| p[RHO] < 0.0 || p[UU] < 0.0)
                .count();
            for (n, r) in rows.chunks_exact(row).enumerate() {
                each(i0 + n, r);
            }
            Ok(())
        };
        match &self.prims {
            Prims::Memory(prims) => check(0, prims)?,
            Prims::File(ds) => {
                let _spare = SpareTop::keep();
                for i0 in (0..h.n[0]).step_by(ROWS_AT_ONCE) {
                    let n = ROWS_AT_ONCE.min(h.n[0] - i0);
                    let rows = ds.read_f64_rows(i0 as u64, n as u64).map_err(|e| {
                        fail(format!(
                            "dataset /prims: rows {i0} to {}: unreadable ({e})",
                            i0 + n - 1
                        ))
                    })?;
                    if rows.len() != n * row {
                        return Err(fail(format!(
                            "dataset /prims: rows {i0} to {}: {} values, expected {}",
                            i0 + n - 1,
                            rows.len(),
                            n * row
                        )));
                    }
                    check(i0, &rows)?;
                }
            }
        }
        if negative > 0 {
            return Err(fail(format!(
                "dataset /prims: {negative} cells with negative RHO or UU, expected none"
            )));
        }
        Ok(())
    }
}

fn read_header(r: &Reader) -> Result<Header, DumpError> {
    if r.has("/header/has_derefine_poles") {
        return Err(r.fail(
            "dataset /header/has_derefine_poles: a grid with derefined poles is not the iharm3d layout"
                .into(),
        ));
    }
    let metric = r.string("/header/metric")?;
    let n = [
        r.count("/header/n1")?,
        r.count("/header/n2")?,
        r.count("/header/n3")?,
    ];
    let gam = r.scalar("/header/gam")?;
    let (gam_e, gam_p) = if r.has("/header/gam_e") {
        (r.scalar("/header/gam_e")?, r.scalar("/header/gam_p")?)
    } else {
        (4.0 / 3.0, 5.0 / 3.0)
    };
    for (name, g) in [("gam", gam), ("gam_e", gam_e), ("gam_p", gam_p)] {
        if !(g > 1.0 && g <= 2.0) {
            return Err(r.fail(format!(
                "dataset /header/{name}: {g}, expected an adiabatic index above 1 and at most 2"
            )));
        }
    }
    let n_prim = r.count("/header/n_prim")?;
    let has_electrons = r.has("/header/has_electrons") && r.scalar("/header/has_electrons")? == 1.0;
    if n_prim < 8 || (has_electrons && n_prim < 10) {
        return Err(r.fail(format!(
            "dataset /header/n_prim: {n_prim}, expected at least {} (RHO, UU, U1-U3, B1-B3{})",
            if has_electrons { 10 } else { 8 },
            if has_electrons { ", KEL, KTOT" } else { "" }
        )));
    }
    let geom = |k: &str| r.scalar(&format!("/header/geom/{k}"));
    let start = [geom("startx1")?, geom("startx2")?, geom("startx3")?];
    let dx = [geom("dx1")?, geom("dx2")?, geom("dx3")?];
    let group = match metric.as_str() {
        "MKS" => "mks",
        "FMKS" | "MMKS" => {
            if r.has("/header/geom/mmks/a") {
                "mmks"
            } else {
                "fmks"
            }
        }
        "BHAC_MKS" => "bhac_mks",
        "EKS" => "eks",
        other => {
            return Err(r.fail(format!(
                "dataset /header/metric: {other:?}, expected one of MKS, FMKS (MMKS), BHAC_MKS, EKS (KORAL's MKS3 dumps are read as KORAL's, not iharm3d's)"
            )));
        }
    };
    let key = |k: &str| format!("/header/geom/{group}/{k}");
    let a = r.scalar(&key("a"))?;
    if a.abs() >= 1.0 {
        return Err(r.fail(format!(
            "dataset {}: {a}, expected a spin inside (-1, 1)",
            key("a")
        )));
    }
    let (r_in, r_out) = if group == "eks" {
        (r.scalar(&key("r_in"))?, r.scalar(&key("r_out"))?)
    } else {
        (
            r.either(&[&key("Rin"), &key("r_in")])?,
            r.either(&[&key("Rout"), &key("r_out")])?,
        )
    };
    let theta = match group {
        "eks" => Theta::Exponential,
        "mks" => Theta::Modified {
            hslope: r.scalar(&key("hslope"))?,
        },
        "bhac_mks" => Theta::Bhac {
            hslope: r.scalar(&key("hslope"))?,
        },
        _ => {
            let alpha = r.scalar(&key("poly_alpha"))?;
            if alpha.fract() != 0.0 || !(1.0..=64.0).contains(&alpha) {
                return Err(r.fail(format!(
                    "dataset {}: {alpha}, expected a whole number from 1 to 64 (FMKS's polynomial is defined below the midplane only then)",
                    key("poly_alpha")
                )));
            }
            Theta::funky(
                r.scalar(&key("hslope"))?,
                r.scalar(&key("poly_xt"))?,
                alpha as i32,
                r.scalar(&key("mks_smooth"))?,
                start[0],
            )
        }
    };
    let header = Header {
        metric,
        n,
        gam,
        gam_e,
        gam_p,
        n_prim,
        start,
        dx,
        a,
        r_in,
        r_out,
        theta,
        t: r.scalar("/t")?,
        dump_cadence: r.scalar("/dump_cadence")?,
        has_electrons,
    };
    check_grid(r, &header)?;
    Ok(header)
}

/// The grid must lie outside the hole's centre and within the sphere.
fn check_grid(r: &Reader, h: &Header) -> Result<(), DumpError> {
    for (i, &d) in h.dx.iter().enumerate() {
        if d <= 0.0 {
            return Err(r.fail(format!(
                "dataset /header/geom/dx{}: {d}, expected a positive width",
                i + 1
            )));
        }
    }
    let span = h.theta.x2_span();
    let x2_end = h.start[1] + h.n[1] as f64 * h.dx[1];
    if h.start[1] < -1e-9 * span || x2_end > span * (1.0 + 1e-9) {
        return Err(r.fail(format!(
            "datasets /header/geom/startx2, dx2: X2 from {} to {x2_end}, expected within [0, {span}] for {}",
            h.start[1], h.metric
        )));
    }
    let x3_end = h.start[2] + h.n[2] as f64 * h.dx[2];
    if h.start[2].abs() > 1e-9 || (x3_end - std::f64::consts::TAU).abs() > 1e-6 {
        return Err(r.fail(format!(
            "datasets /header/geom/startx3, dx3: X3 from {} to {x3_end}, expected the whole circle, 0 to 2 pi",
            h.start[2]
        )));
    }
    if !(h.r_in > 0.0 && h.r_out > h.r_in) {
        return Err(r.fail(format!(
            "the grid's radii {} to {}: expected 0 < r_in < r_out",
            h.r_in, h.r_out
        )));
    }
    Ok(())
}

/// The dump's /prims, its shape checked.
fn prims_dataset(r: &Reader, h: &Header) -> Result<hdf5_pure::Dataset, DumpError> {
    let ds = r.dataset("/prims")?;
    let shape = ds
        .shape()
        .map_err(|e| r.fail(format!("dataset /prims: unreadable shape ({e})")))?;
    let want = [h.n[0], h.n[1], h.n[2], h.n_prim].map(|x| x as u64);
    if shape != want {
        return Err(r.fail(format!(
            "dataset /prims: shape {shape:?}, expected [n1, n2, n3, n_prim] = {want:?}"
        )));
    }
    Ok(ds)
}

/// Writes `header` and `prims` as an iharm3d-format dump at `path`, as
/// iharm3d does (scalars as scalar datasets, the metric's name a
/// fixed-length string, its parameters under /header/geom/<metric>/),
/// through a temporary file renamed into place.
pub fn write(path: &Path, h: &Header, prims: &[f64]) -> anyhow::Result<()> {
    use hdf5_pure::GroupBuilder;
    fn f64s(g: &mut GroupBuilder, name: &str, x: f64) {
        g.create_dataset(name).with_f64_data(&[x]).with_shape(&[]);
    }
    fn i32s(g: &mut GroupBuilder, name: &str, x: i32) {
        g.create_dataset(name).with_i32_data(&[x]).with_shape(&[]);
    }
    let mut b = FileBuilder::new();
    let mut header = b.create_group("header");
    header
        .create_dataset("metric")
        .with_ascii_strings_sized(&[&h.metric], 20)?
        .with_shape(&[]);
    for (k, n) in h.n.iter().enumerate() {
        i32s(&mut header, &format!("n{}", k + 1), *n as i32);
    }
    i32s(&mut header, "n_prim", h.n_prim as i32);
    i32s(&mut header, "has_electrons", h.has_electrons as i32);
    f64s(&mut header, "gam", h.gam);
    f64s(&mut header, "gam_e", h.gam_e);
    f64s(&mut header, "gam_p", h.gam_p);
    let mut geom = header.create_group("geom");
    for k in 0..3 {
        f64s(&mut geom, &format!("startx{}", k + 1), h.start[k]);
        f64s(&mut geom, &format!("dx{}", k + 1), h.dx[k]);
    }
    let name = match h.theta {
        Theta::Exponential => "eks",
        Theta::Modified { .. } => "mks",
        Theta::Bhac { .. } => "bhac_mks",
        Theta::Funky { .. } => "mmks",
    };
    let mut m = geom.create_group(name);
    f64s(&mut m, "a", h.a);
    f64s(&mut m, "r_in", h.r_in);
    f64s(&mut m, "r_out", h.r_out);
    match h.theta {
        Theta::Exponential => {}
        Theta::Modified { hslope } | Theta::Bhac { hslope } => f64s(&mut m, "hslope", hslope),
        Theta::Funky {
            hslope,
            poly_xt,
            poly_alpha,
            mks_smooth,
            ..
        } => {
            f64s(&mut m, "hslope", hslope);
            f64s(&mut m, "poly_xt", poly_xt);
            f64s(&mut m, "poly_alpha", poly_alpha as f64);
            f64s(&mut m, "mks_smooth", mks_smooth);
        }
    }
    geom.add_group(m.finish());
    header.add_group(geom.finish());
    b.add_group(header.finish());
    b.create_dataset("t").with_f64_data(&[h.t]).with_shape(&[]);
    b.create_dataset("dump_cadence")
        .with_f64_data(&[h.dump_cadence])
        .with_shape(&[]);
    b.create_dataset("prims")
        .with_f64_data(prims)
        .with_shape(&[h.n[0], h.n[1], h.n[2], h.n_prim].map(|x| x as u64));
    let temp = crate::files::Temp::new(path)?;
    b.finish_to(std::io::BufWriter::new(temp.file()))?;
    temp.sync()?;
    temp.persist()
}
