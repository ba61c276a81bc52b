//! The output plan: which files a render writes, the checks made before
//! any work (against the inputs, each other, read-only files, the memory),
//! and the writes, all of a set or none.

use crate::config::{Override, SceneConfig};
use crate::files::{Batch, Plan};
use crate::film::Film;
use crate::output::{stage_film, stage_png};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// A plan whose inputs are the scene file `config` and every file the
/// scene reads.
pub fn plan_of(config: &Path, cfg: &SceneConfig) -> Plan {
    let mut plan = Plan::new();
    plan.input("the scene file", config);
    for (key, path) in crate::files::scene_inputs(cfg) {
        plan.input(key, path);
    }
    plan
}

/// Refuses to replace an existing image named by the scene file (not on
/// the command line, whose `overrides` are given) with one of another
/// size, unless `overwrite`: a reduced trial render must not silently
/// replace a full-size result (such as the shipped images in img/).
pub fn guard_outputs(
    overrides: &[Override],
    overwrite: bool,
    files: &[(PathBuf, (u32, u32))],
) -> Result<()> {
    if overwrite || crate::config::from_cli(overrides, "image.png") {
        return Ok(());
    }
    for (path, (w, h)) in files {
        if let Ok((ew, eh)) = image::image_dimensions(path)
            && (ew, eh) != (*w, *h)
        {
            bail!(
                "{} exists at {ew} x {eh} and this render is {w} x {h}: name another output with --set image.png=PATH (every output follows it), or pass --overwrite to replace it",
                path.display()
            );
        }
    }
    Ok(())
}

/// Refuses a job whose memory (the scene's assets, its films and the
/// copies its outputs make) would not fit, before it starts.
pub fn check_memory(cfg: &SceneConfig, job: crate::memory::Job, what: &str) -> Result<()> {
    crate::memory::film(cfg, job, crate::memory::assets(cfg))
        .check(what)
        .map_err(anyhow::Error::msg)
}

/// The files `render` writes for a scene: image.png, the EXR, with
/// `[stereo]` the eyes and their composites, and with `[observe]` the
/// flux spectrum (named after image.png).
pub struct Outputs {
    main: Vec<PathBuf>,
    stereo: Option<[PathBuf; 4]>,
    /// An observed scene's total flux density at each frequency,
    /// `<image>.spectrum.csv`.
    spectrum: Option<PathBuf>,
    size: (u32, u32),
}

impl Outputs {
    /// The outputs `cfg` names.
    pub fn of(cfg: &SceneConfig) -> Outputs {
        let img = &cfg.image;
        let stem = img.png.with_extension("");
        let stereo_name = |tag: &str| PathBuf::from(format!("{}_{tag}.png", stem.display()));
        Outputs {
            main: std::iter::once(&img.png).chain(&img.exr).cloned().collect(),
            stereo: cfg
                .stereo
                .as_ref()
                .map(|_| ["left", "right", "side_by_side", "anaglyph"].map(stereo_name)),
            spectrum: cfg
                .observe
                .as_ref()
                .map(|_| PathBuf::from(format!("{}.spectrum.csv", stem.display()))),
            size: (img.width, img.height),
        }
    }

    /// Checks every output against the inputs (the scene file `config`,
    /// the scene's files and `more`) and each other, that it can be
    /// written, and that it would not replace an image of another size that
    /// the scene file names (unless `overwrite`).
    pub fn check(
        &self,
        config: &Path,
        overrides: &[Override],
        cfg: &SceneConfig,
        more: &[(String, PathBuf)],
        overwrite: bool,
    ) -> Result<()> {
        let mut plan = plan_of(config, cfg);
        plan.inputs.extend(more.iter().cloned());
        for (p, key) in self.main.iter().zip(["image.png", "image.exr"]) {
            plan.output(key, p);
        }
        if let Some(p) = &self.spectrum {
            plan.output("the flux spectrum", p);
        }
        let mut sized: Vec<(PathBuf, (u32, u32))> =
            self.main.iter().map(|p| (p.clone(), self.size)).collect();
        if let Some(st) = &self.stereo {
            for (p, tag) in st
                .iter()
                .zip(["left eye", "right eye", "side by side", "anaglyph"])
            {
                plan.output(format!("the stereo {tag}"), p);
            }
            sized.extend(st.iter().enumerate().map(|(i, p)| {
                let w = if i == 2 { 2 * self.size.0 } else { self.size.0 };
                (p.clone(), (w, self.size.1))
            }));
        }
        plan.check()?;
        guard_outputs(overrides, overwrite, &sized)
    }

    /// Writes the image, the EXR and the stereo files, all or none, then
    /// calls `done` with the names of the image and EXR.
    pub fn write(
        &self,
        cfg: &SceneConfig,
        film: &Film,
        eyes: Option<&(Film, Film)>,
        quiet: bool,
        done: impl FnOnce(&[String]),
    ) -> Result<()> {
        let img = &cfg.image;
        let mut batch = Batch::new();
        stage_film(&mut batch, cfg, film, &img.png, img.exr.as_deref(), &[])?;
        if let (Some(files), Some((left, right))) = (&self.stereo, eyes) {
            let srgb = |f: &Film| crate::output::picture(cfg, &crate::output::displayed(cfg, f));
            let eyes = [srgb(left), srgb(right)];
            let (w, h) = (film.width, film.height);
            stage_png(&mut batch, &files[0], w, h, &eyes[0])?;
            stage_png(&mut batch, &files[1], w, h, &eyes[1])?;
            let sbs = crate::post::side_by_side(w as usize, h as usize, &eyes[0], &eyes[1]);
            stage_png(&mut batch, &files[2], 2 * w, h, &sbs)?;
            let anaglyph = crate::post::anaglyph(&eyes[0], &eyes[1]);
            stage_png(&mut batch, &files[3], w, h, &anaglyph)?;
        }
        let spectrum = self
            .spectrum
            .as_ref()
            .filter(|_| !film.frequencies.is_empty());
        if let Some(p) = spectrum {
            let csv = spectrum_csv(film);
            batch.write(p, |w| Ok(std::io::Write::write_all(w, csv.as_bytes())?))?;
        }
        batch.commit()?;
        let written: Vec<String> = self
            .main
            .iter()
            .chain(spectrum)
            .map(|p| p.display().to_string())
            .collect();
        done(&written);
        if let Some(files) = &self.stereo
            && eyes.is_some()
            && !quiet
        {
            let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
            eprintln!("stereo pair -> {}", names.join(", "));
        }
        Ok(())
    }
}

/// An observed film's total flux density at each frequency, as CSV: a
/// header, then `frequency_hz,flux_jy` rows in the scene's order (every
/// digit a float64 keeps).
pub fn spectrum_csv(film: &Film) -> String {
    let mut csv = String::from("frequency_hz,flux_jy\n");
    for (f, jy) in film.frequencies.iter().zip(film.total_flux()) {
        csv += &format!("{f:e},{jy:e}\n");
    }
    csv
}
