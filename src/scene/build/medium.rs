//! `[medium]` and `[observe]`: plasma in physical units and how it is
//! observed, checked and built.

use super::super::{SceneError, invalid};
use crate::config::MediumConfig;
use crate::config::{DiskEmission, SceneConfig};
use crate::physics::Spacetime;
use crate::physics::kerr::Kerr;
use crate::transfer::gold::{self, Gold};
use crate::transfer::{Medium, Observe, Riaf, RiafProfile, Uniform, VolumeGas};
use crate::units::cgs::PARSEC as PARSEC_CM;
use crate::volume::VolumeDisk;

/// The medium and its observation: a scene observed in physical units
/// holds a medium (`[medium]`, or the volumetric disk's gas), a thin disk
/// (a blackbody at its temperature), a blackbody sky, or several of them;
/// a `[medium]` is never without its observation. `volume` is the scene's
/// volumetric disk, `r_s` its hole's Schwarzschild radius (m).
pub(super) fn medium(
    config: &SceneConfig,
    spacetime: Option<Spacetime>,
    (volume, r_s): (Option<&VolumeDisk>, f64),
) -> Result<Option<Observe>, SceneError> {
    let o = match (&config.medium, &config.observe) {
        (None, None) => return Ok(None),
        (Some(_), None) => {
            return Err(invalid(
                "medium",
                "[medium] without [observe]",
                "an [observe] table with the source's distance (pc) and the frequency (Hz): a medium's light is in physical units",
            ));
        }
        (None, Some(_))
            if !thin_disk(config) && config.volume.is_none() && config.sky.blackbody.is_none() =>
        {
            return Err(invalid(
                "observe",
                "[observe] without [medium]",
                "a [medium] or [volume] table, a [disk] with emission = \"thin\" or a sky.blackbody: [observe] gives the janskys of their light",
            ));
        }
        (_, Some(o)) => o,
    };
    let Some(st) = spacetime else {
        return Err(invalid(
            "physics.model",
            config.physics.model,
            "\"gr\": an observed scene is defined in the hole's spacetime, which the seed model has none of",
        ));
    };
    for (key, present) in [
        ("cloud", !config.clouds.is_empty()),
        ("object", !config.objects.is_empty()),
    ] {
        if present {
            return Err(invalid(
                key,
                format!("[{key}] with [observe]"),
                "no such table: an observed scene holds a medium ([medium] or [volume]) and a thin [disk] (the clouds and objects have no emission in physical units)",
            ));
        }
    }
    if let Some(v) = &config.volume {
        physical_volume(v, config)?;
    }
    if let Some(d) = &config.disk {
        physical_disk(d)?;
    }
    physical_sky(&config.sky)?;
    if config.spectral.enabled {
        return Err(invalid(
            "spectral.enabled",
            true,
            "false with [observe]: the frequencies are [observe].frequency's",
        ));
    }
    let Some(m) = &config.medium else {
        // The volumetric disk's gas, built with the scene's other gas.
        let gas = volume.map(|v| Medium::Volume(Box::new(VolumeGas::new(v.clone(), r_s * 100.0))));
        return Ok(Some(observe(o, gas, config)?));
    };
    let medium = match m {
        MediumConfig::Gold2020(g) => Medium::Gold2020(gold2020(g, st)?),
        MediumConfig::Uniform(u) => Medium::Uniform(uniform(u, st)?),
        MediumConfig::Synchrotron(f) => Medium::Riaf(riaf(f, st)?),
        MediumConfig::Grmhd(g) => Medium::Grmhd(Box::new(grmhd(g, st, 50.0 * r_s)?)),
    };
    Ok(Some(observe(o, Some(medium), config)?))
}

/// A GRMHD dump's plasma about the hole `st` of `cm_per_m` cm per M.
fn grmhd(
    g: &crate::config::GrmhdConfig,
    st: Spacetime,
    cm_per_m: f64,
) -> Result<crate::transfer::grmhd::Grmhd, SceneError> {
    use crate::config::GrmhdElectrons;
    use crate::transfer::grmhd::torus::{TorusOptions, torus_dump};
    use crate::transfer::grmhd::{Electrons, Grmhd, Settings, dump::Dump};
    for (key, x, what) in [
        (
            "m_unit",
            g.m_unit,
            "the simulation's mass unit in grams (ipole's M_unit)",
        ),
        ("r_high", g.r_high, "T_i/T_e where the plasma beta is high"),
        ("r_low", g.r_low, "T_i/T_e where the plasma beta is low"),
        (
            "beta_crit",
            g.beta_crit,
            "the beta where R turns from R_low to R_high",
        ),
        (
            "sigma_cut",
            g.sigma_cut,
            "the magnetisation b^2/rho above which the plasma is cut",
        ),
        ("r_max", g.r_max, "a radius in M beyond which nothing emits"),
    ] {
        if !(x.is_finite() && x > 0.0) {
            return Err(invalid(
                &format!("medium.{key}"),
                x,
                &format!("a finite number > 0: {what}"),
            ));
        }
    }
    if !(0.0..90.0).contains(&g.polar_cut) {
        return Err(invalid(
            "medium.polar_cut",
            g.polar_cut,
            "an angle from the axis in degrees, from 0 to below 90",
        ));
    }
    if let Some(f) = g.flux
        && !(f.jy.is_finite() && f.jy > 0.0)
    {
        return Err(invalid(
            "medium.flux",
            Text(format!("{} Jy", f.jy)),
            "a positive flux density (\"0.5 Jy\"): the total at the first observed frequency that m_unit is fitted to",
        ));
    }
    let dump = match (&g.dump, &g.torus) {
        (Some(path), None) => Dump::read(path)?,
        (None, Some(t)) => {
            let o = TorusOptions::parse(&t.metric, &t.grid, t.funnel).map_err(|e| {
                invalid(
                    "medium.torus",
                    Text(e.clone()),
                    "the torus as `blackhole torus` takes it",
                )
            })?;
            torus_dump(
                &o,
                &format!("the generated torus ({} {})", t.metric, t.grid),
            )
        }
        _ => {
            return Err(SceneError::Keys(
                "[medium] kind = \"grmhd\" takes one of dump (an iharm3d-format file) and torus (the Fishbone-Moncrief torus built in memory)".into(),
            ));
        }
    };
    let path = dump.path.clone();
    let spin = st.spin();
    if (dump.header.a - spin).abs() > 1e-6 {
        return Err(invalid(
            "black_hole.spin",
            spin,
            &format!(
                "the dump's spin, {} ({}, dataset /header/geom/.../a)",
                dump.header.a,
                path.display()
            ),
        ));
    }
    let electrons = match g.electrons {
        GrmhdElectrons::RHigh => Electrons::RHigh {
            r_high: g.r_high,
            r_low: g.r_low,
            beta_crit: g.beta_crit,
        },
        GrmhdElectrons::Dump if dump.header.has_electrons => Electrons::Dump,
        GrmhdElectrons::Dump => {
            return Err(invalid(
                "medium.electrons",
                "dump",
                &format!(
                    "\"r_high\": the dump {} has no electron entropy (/header/has_electrons is not 1)",
                    path.display()
                ),
            ));
        }
    };
    let settings = Settings {
        m_unit: g.m_unit,
        electrons,
        sigma_cut: g.sigma_cut,
        r_max: g.r_max,
        polar_cut: g.polar_cut.to_radians(),
        flux: g.flux.map(|f| f.jy),
    };
    Ok(Grmhd::new(&dump, settings, cm_per_m)?)
}

/// An observed scene's volumetric disk: its gas is the medium, shining by
/// Planck's function at its temperature (no luminance of its own), as it
/// is at the scene's time 0.
fn physical_volume(
    v: &crate::config::VolumeConfig,
    config: &SceneConfig,
) -> Result<(), SceneError> {
    if config.medium.is_some() {
        return Err(invalid(
            "volume",
            "[volume] with [medium]",
            "one of them: an observed scene has one medium",
        ));
    }
    if let Some(e) = v.emission {
        return Err(invalid(
            "volume.emission",
            e,
            "nothing with [observe]: the gas's source function is Planck's at its temperature (volume.peak_kelvin), in physical units",
        ));
    }
    if config.animation.is_some() {
        return Err(invalid(
            "animation",
            "[animation] with an observed [volume]",
            "a still: the volume's turbulence does not turn in observed scenes",
        ));
    }
    Ok(())
}

/// An observed scene's sky: dark, or a blackbody at infinity in physical
/// units (the cosmic microwave background at 2.7255 K, say); a panorama,
/// a catalogue, a colour or a multiplier has none.
fn physical_sky(s: &crate::config::SkyConfig) -> Result<(), SceneError> {
    let expected = "nothing with [observe]: sky.color = [0.0, 0.0, 0.0] for a dark sky, or sky.blackbody = T (K) for a blackbody at infinity in physical units (2.7255 for the cosmic microwave background)";
    if let Some(t) = &s.texture {
        return Err(invalid("sky.texture", t.display(), expected));
    }
    if let Some(t) = &s.stars {
        return Err(invalid("sky.stars", t.display(), expected));
    }
    if let Some(c) = s.color
        && c != [0.0; 3]
    {
        return Err(invalid("sky.color", format!("{c:?}"), expected));
    }
    if s.blackbody.is_some() && s.intensity != 1.0 {
        return Err(invalid(
            "sky.intensity",
            s.intensity,
            "1 with [observe]: the blackbody sky is in physical units",
        ));
    }
    Ok(())
}

/// Whether the scene's disk is the physical thin disk.
fn thin_disk(config: &SceneConfig) -> bool {
    config
        .disk
        .as_ref()
        .is_some_and(|d| d.emission == DiskEmission::Thin)
}

/// An observed scene's disk: the thin disk's blackbody light alone, which
/// is in physical units (a texture's pattern and a multiplier are not).
fn physical_disk(d: &crate::config::DiskConfig) -> Result<(), SceneError> {
    if d.emission != DiskEmission::Thin {
        return Err(invalid(
            "disk.emission",
            "\"texture\"",
            "\"thin\" with [observe]: only the thin disk's blackbody light is in physical units",
        ));
    }
    if let Some(t) = &d.texture {
        return Err(invalid(
            "disk.texture",
            t.display(),
            "nothing with [observe]: a texture's pattern has no physical units",
        ));
    }
    if d.intensity != 1.0 {
        return Err(invalid(
            "disk.intensity",
            d.intensity,
            "1 with [observe]: the thin disk's light is in physical units",
        ));
    }
    Ok(())
}

fn gold2020(g: &crate::config::Gold2020Config, st: Spacetime) -> Result<Gold, SceneError> {
    let base = match g.test {
        None => None,
        Some(n) if (1..=5).contains(&n) => Some(gold::TESTS[n as usize - 1]),
        Some(n) => {
            return Err(invalid(
                "medium.test",
                n,
                "1 to 5: Gold et al. 2020's tests",
            ));
        }
    };
    let spin = st.spin();
    if let (Some(n), Some(t)) = (g.test, base)
        && spin != t.4
    {
        return Err(invalid(
            "black_hole.spin",
            spin,
            &format!(
                "{} for medium.test = {n} (the test is defined at that spin)",
                t.4
            ),
        ));
    }
    let pick = |key: &str, v: Option<f64>, from_test: Option<f64>| -> Result<f64, SceneError> {
        match v.or(from_test) {
            Some(x) if x.is_finite() => Ok(x),
            Some(x) => Err(invalid(&format!("medium.{key}"), x, "a finite number")),
            None => Err(invalid(
                &format!("medium.{key}"),
                "missing",
                "a value, or medium.test = 1..5 to take the test's",
            )),
        }
    };
    let a_abs = pick("A", g.a, base.map(|t| t.0))?;
    let alpha = pick("alpha", g.alpha, base.map(|t| t.1))?;
    let h = pick("h", g.h, base.map(|t| t.2))?;
    let l0 = pick("l0", g.l0, base.map(|t| t.3))?;
    for (key, x) in [("A", a_abs), ("h", h), ("n0", g.n0)] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(invalid(
                &format!("medium.{key}"),
                x,
                "a finite number >= 0 (a density or an absorption is never negative)",
            ));
        }
    }
    if !(g.nu_p.is_finite() && g.nu_p > 0.0) {
        return Err(invalid("medium.nu_p", g.nu_p, "a positive frequency (Hz)"));
    }
    Ok(Gold {
        a_abs,
        alpha,
        h,
        l0,
        n0: g.n0,
        nu_p: g.nu_p,
    })
}

fn uniform(u: &crate::config::UniformConfig, st: Spacetime) -> Result<Uniform, SceneError> {
    for (key, x) in [
        ("emission", u.emission),
        ("absorption", u.absorption),
        ("inner", u.inner),
    ] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(invalid(
                &format!("medium.{key}"),
                x,
                "a finite number >= 0 (an emission, absorption or radius is never negative)",
            ));
        }
    }
    if !u.alpha.is_finite() {
        return Err(invalid("medium.alpha", u.alpha, "a finite number"));
    }
    if !(u.nu_p.is_finite() && u.nu_p > 0.0) {
        return Err(invalid("medium.nu_p", u.nu_p, "a positive frequency (Hz)"));
    }
    // The shell lies outside the horizon, where gas can be at rest.
    // (The spacetime's radii are in r_s, M's half.)
    let horizon = 2.0 * st.horizon();
    if !(u.inner > horizon) {
        return Err(invalid(
            "medium.inner",
            u.inner,
            &format!(
                "a radius outside the horizon at {horizon:.6} M (gas cannot stay at rest inside it)"
            ),
        ));
    }
    if !(u.outer.is_finite() && u.outer > u.inner) {
        return Err(invalid(
            "medium.outer",
            u.outer,
            &format!("a finite radius above medium.inner = {} (M)", u.inner),
        ));
    }
    Ok(Uniform::new(
        u.inner,
        u.outer,
        (u.emission, u.absorption),
        u.alpha,
        u.nu_p,
    ))
}

fn riaf(f: &crate::config::SynchrotronConfig, st: Spacetime) -> Result<Riaf, SceneError> {
    for (key, x, what) in [
        ("density", f.density, "a density (cm^-3)"),
        ("temperature", f.temperature, "a temperature (K)"),
        (
            "thickness",
            f.thickness,
            "a width (H of exp(-z^2 / (2 H^2 rho^2)))",
        ),
        ("beta", f.beta, "a pressure ratio"),
    ] {
        if !(x.is_finite() && x > 0.0) {
            return Err(invalid(
                &format!("medium.{key}"),
                x,
                &format!("a finite number > 0: {what}"),
            ));
        }
    }
    for (key, x) in [
        ("density_index", f.density_index),
        ("temperature_index", f.temperature_index),
    ] {
        if !x.is_finite() {
            return Err(invalid(&format!("medium.{key}"), x, "a finite number"));
        }
    }
    for (key, x) in [("keplerian", f.keplerian), ("infall", f.infall)] {
        if !(0.0..=1.0).contains(&x) {
            return Err(invalid(
                &format!("medium.{key}"),
                x,
                "a number from 0 to 1 (a blend of the Keplerian motion and the frame's or free fall)",
            ));
        }
    }
    let horizon = 2.0 * st.horizon();
    if !(f.outer.is_finite() && f.outer > horizon) {
        return Err(invalid(
            "medium.outer",
            f.outer,
            &format!("a finite radius outside the horizon at {horizon:.6} M"),
        ));
    }
    Ok(Riaf::new(
        RiafProfile {
            density: f.density,
            temperature: f.temperature,
            density_index: f.density_index,
            temperature_index: f.temperature_index,
            thickness: f.thickness,
            beta: f.beta,
            keplerian: f.keplerian,
            infall: f.infall,
            outer: f.outer,
        },
        Kerr::new(st.spin()),
    ))
}

/// A value shown as written in a message (no quotes).
struct Text(String);

impl std::fmt::Debug for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// The particle horizon's comoving distance (pc, Planck 2018: 46.5 Gly):
/// nothing is observed from farther away.
const HORIZON_PC: f64 = 14.26e9;

fn observe(
    o: &crate::config::ObserveConfig,
    medium: Option<Medium>,
    config: &SceneConfig,
) -> Result<Observe, SceneError> {
    use crate::config::quantity::{distance_text, frequency_text};
    let pc = o.distance.pc;
    let shown = |pc: f64| Text(distance_text(pc));
    if !(pc.is_finite() && pc > 0.0) {
        return Err(invalid(
            "observe.distance",
            Text(format!("{pc} pc")),
            "a positive distance (a number in parsecs, or \"8.178 kpc\")",
        ));
    }
    // Earth sees the scene from beyond the camera, whose angles it scales
    // by r_cam / D; and from within the observable universe.
    let camera_pc = glam::DVec3::from_array(config.camera.position).length() / crate::units::PARSEC;
    if pc <= camera_pc {
        return Err(invalid(
            "observe.distance",
            shown(pc),
            &format!(
                "more than the camera's distance from the hole ({}): Earth sees the scene from beyond the camera",
                distance_text(camera_pc)
            ),
        ));
    }
    if pc > HORIZON_PC {
        return Err(invalid(
            "observe.distance",
            shown(pc),
            "at most 14.26 Gpc, the observable universe's radius",
        ));
    }
    // Each pixel's janskys are its intensity (cgs) times its solid angle
    // seen from Earth over 1e-23: that factor must be a normal number in
    // f32 and f64, or the images hold 0 or infinity.
    let fov = config.camera.fov.to_radians();
    let pixel = (fov / config.image.height.max(1) as f64).powi(2);
    let jy_per_cgs = pixel * (camera_pc / pc).powi(2) / crate::units::cgs::JANSKY;
    if !(jy_per_cgs.is_normal() && (jy_per_cgs as f32).is_normal()) {
        return Err(invalid(
            "observe.distance",
            shown(pc),
            &format!(
                "a distance at which a pixel's flux density is a finite, non-zero 32-bit number (a pixel's solid angle seen from there is {:e} sr)",
                pixel * (camera_pc / pc).powi(2)
            ),
        ));
    }
    sky_position(o)?;
    let frequencies = o.frequency.list();
    if frequencies.is_empty() {
        return Err(invalid(
            "observe.frequency",
            "[]",
            "at least one frequency (a number in Hz, or \"230 GHz\")",
        ));
    }
    if let Some(&f) = frequencies.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        return Err(invalid(
            "observe.frequency",
            Text(format!("{f} Hz")),
            "positive, finite frequencies (a number in Hz, or \"230 GHz\")",
        ));
    }
    // Each frequency is a channel of the EXR and a row of the spectrum:
    // no two may share a name.
    for (i, &a) in frequencies.iter().enumerate() {
        let name = crate::film::flux_channel_name(a);
        if let Some(&b) = frequencies[..i]
            .iter()
            .find(|&&b| crate::film::flux_channel_name(b) == name)
        {
            let what = if a == b {
                format!("{} twice", frequency_text(a))
            } else {
                format!("{a:e} Hz and {b:e} Hz, both channel {name}")
            };
            return Err(invalid(
                "observe.frequency",
                Text(what),
                "distinct frequencies, apart by more than a millionth of a GHz (each is a channel jy.<GHz> of the EXR and a row of the spectrum)",
            ));
        }
    }
    Ok(Observe {
        medium,
        distance_cm: pc * PARSEC_CM,
        frequencies,
    })
}

/// Where the source lies on the sky and what it is called, as the FITS
/// files say it: right ascension in [0, 360) and declination in [-90, 90]
/// degrees, a finite date, a name of printable ASCII that fits a FITS card.
fn sky_position(o: &crate::config::ObserveConfig) -> Result<(), SceneError> {
    if let Some(ra) = o.ra
        && !(0.0..360.0).contains(&ra)
    {
        return Err(invalid("observe.ra", ra, "degrees from 0 up to 360"));
    }
    if let Some(dec) = o.dec
        && !(-90.0..=90.0).contains(&dec)
    {
        return Err(invalid("observe.dec", dec, "degrees from -90 to 90"));
    }
    if let Some(mjd) = o.mjd
        && !mjd.is_finite()
    {
        return Err(invalid("observe.mjd", mjd, "a finite Modified Julian Date"));
    }
    if let Some(name) = &o.source
        && (name.len() > 68 || !name.chars().all(|c| c.is_ascii() && !c.is_ascii_control()))
    {
        return Err(invalid(
            "observe.source",
            name,
            "a name of at most 68 printable ASCII characters (a FITS card's)",
        ));
    }
    Ok(())
}
