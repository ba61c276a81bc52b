//! Building a scene in steps: each part of the file checked and built by
//! its own short function (`image`, `lens`, `disk`, `sky`, `gas`,
//! `objects`, `limits`), then put together, with the animation's clock.

mod disk;
mod gas;
mod image;
mod lens;
mod limits;
mod medium;
mod objects;
mod sky;

use super::{MAX_PHASE, Scene, SceneError, invalid};
use crate::animation::{DiskRotation, Pose, Timeline};
use crate::config::{SceneConfig, SpectralConfig};
use crate::disk::DiskMaterial;
use crate::sky::Sky;
use crate::spectral::SpectralContext;
use crate::spectrum::sampled::MAX_WAVELENGTHS;

/// The animation's clock and paths, if the scene has one.
fn timeline(
    config: &SceneConfig,
    r_s: f64,
    spacetime: crate::physics::Spacetime,
) -> Result<Option<Timeline>, SceneError> {
    config
        .animation
        .as_ref()
        .map(|a| {
            Timeline::new(a, r_s, spacetime).map_err(|(key, value, expected)| SceneError::Invalid {
                key,
                value,
                expected,
            })
        })
        .transpose()
}

impl Scene {
    /// Validates the configuration and loads its assets, part by part; no
    /// render starts and no file is written until the whole scene is valid.
    pub fn build(config: SceneConfig) -> Result<Scene, SceneError> {
        image::check(&config)?;
        let r_s = lens::schwarzschild(&config)?;
        let spacetime = lens::spacetime(&config)?;
        let pose = lens::pose(&config, r_s, spacetime)?;
        let model = lens::model(&config.physics, spacetime)?;
        let mut camera = lens::camera(&config, r_s, pose, spacetime)?;
        let motion = super::motion::CameraMotion::of(&config)?;
        motion.apply(&mut camera, model.spacetime(), || glam::DVec3::ZERO, 0.0)?;
        let mut warnings = image::warnings(&config);
        let spectral = spectral(&config.spectral)?;
        // Before anything loads: a scene whose assets cannot fit is refused
        // now, not after minutes of decoding.
        crate::memory::assets(&config)
            .check("loading the scene")
            .map_err(SceneError::Memory)?;
        let disk = disk::disk(&config, spectral.is_some(), spacetime, &mut warnings)?;
        let sky = sky::sky(&config, spectral.is_some())?;
        let volume = gas::volume(&config, disk.is_some(), spacetime)?;
        let clouds = gas::clouds(&config, r_s, spectral.as_ref())?;
        let observe = medium::medium(&config, model.spacetime(), (volume.as_ref(), r_s))?;
        let objects = config
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| objects::object(i, o, r_s))
            .collect::<Result<Vec<_>, _>>()?;
        objects::outside_ergosphere(&objects, spacetime)?;
        let lighting = objects::lights(&config, disk.as_ref())?;
        let limits = limits::limits(
            disk.as_ref(),
            &objects,
            (
                volume.as_ref(),
                observe.as_ref().and_then(|o| o.medium.as_ref()),
            ),
            &clouds,
            config.physics.max_steps,
        );
        if spectral.is_some() {
            prepare_uplift(&sky, disk.as_ref(), &objects);
        }
        let animation = timeline(&config, r_s, model.spacetime().unwrap_or_default())?;
        let base_pose = Pose::from(&config.camera);
        let light_travel_time = animation.as_ref().is_some_and(|a| a.light_travel_time);
        let observables = config.image.observables.clone();
        let timed = light_travel_time || observables.contains(&crate::film::Observable::Time);
        // Timed scenes too where the spacetime's closed form keeps time.
        // An observed scene's gas is its medium, which closed-form rays
        // carry (Schwarzschild's segments and Kerr's stretches, with the
        // azimuth where the medium needs it); other scenes' gas and
        // objects are met by the integrator.
        let closed_form = config.physics.closed_form
            && model
                .spacetime()
                .is_some_and(|st| st.closed_form_keeps_time() || !timed)
            && objects.is_empty()
            && clouds.is_empty()
            && (volume.is_none() || observe.is_some());
        // An observed scene keeps its janskys at each frequency.
        let keep_spectra = spectral.is_some() && config.spectral.exr_layers || observe.is_some();
        let bloom_bands = spectral.is_some() && config.bloom.as_ref().is_some_and(|b| b.spectral);
        let footprints = footprints_wanted(&observables, disk.as_ref(), &sky);
        let object_footprints = objects.iter().any(|o| {
            o.material.texture.is_some() && o.material.filter == crate::config::Filter::Footprint
        });
        let mut scene = Scene {
            footprints,
            object_footprints,
            r_s,
            camera,
            model,
            limits,
            disk,
            sky,
            spectral,
            volume,
            clouds,
            observe,
            objects,
            glow_base: lighting.glow.clone(),
            lighting,
            warnings,
            time: 0.0,
            rotation: animation
                .as_ref()
                .map_or(DiskRotation::None, |a| a.rotation),
            light_travel_time,
            timed,
            observables,
            closed_form,
            samples: config.image.samples,
            max_samples: config.image.max_samples(),
            adaptive: config.image.adaptive(),
            seed: config.image.seed,
            keep_spectra,
            bloom_bands,
            animation,
            base_pose,
            motion,
            config: config.clone(),
        };
        if let Some(a) = scene.animation.clone() {
            let eps = f64::EPSILON;
            scene.check_phase("animation.start", a.start, MAX_PHASE, eps)?;
            scene.check_phase("animation.duration", a.start + a.duration, MAX_PHASE, eps)?;
            scene.check_camera_path(&a)?;
            scene.set_time(a.start)?;
        }
        scene.build_filters();
        Ok(scene)
    }

    /// Builds the mip levels the footprint filter reads, here rather than
    /// on a render's first lookup (which would wait on it).
    fn build_filters(&self) {
        use crate::config::Filter;
        if let Some(d) = self.disk.as_ref().filter(|d| d.filter == Filter::Footprint) {
            match &d.material {
                DiskMaterial::Rgb(t) => t.build_pyramid(),
                DiskMaterial::Spectral(s) => s.build_pyramid(),
            }
        }
        match &self.sky {
            Sky::Panorama {
                texture, filter, ..
            } if *filter == Filter::Footprint => texture.build_pyramid(),
            Sky::Stars { map, filter, .. } if *filter == Filter::Footprint => map.build_pyramids(),
            _ => {}
        }
        for o in &self.objects {
            if let Some(t) = o.material.texture.as_ref()
                && o.material.filter == Filter::Footprint
            {
                t.build_pyramid();
            }
        }
    }
}

/// The wavelengths and tables of a spectral render, or none for RGB.
fn spectral(sc: &SpectralConfig) -> Result<Option<SpectralContext>, SceneError> {
    if !sc.enabled {
        // Spectral keys without spectral.enabled are warned about with the
        // other settings that do nothing.
        return Ok(None);
    }
    if !(2..=MAX_WAVELENGTHS as u32).contains(&sc.wavelengths) {
        return Err(invalid(
            "spectral.wavelengths",
            sc.wavelengths,
            &format!("expected 2 to {MAX_WAVELENGTHS} samples over 380-780 nm"),
        ));
    }
    Ok(Some(SpectralContext::new(sc)))
}

/// RGB content of a spectral render is uplifted as it is met: the table is
/// built before any render starts where there is some.
fn prepare_uplift(sky: &Sky, disk: Option<&crate::disk::Disk>, objects: &[crate::objects::Object]) {
    if matches!(sky, Sky::Panorama { .. })
        || disk.is_some_and(|d| matches!(d.material, DiskMaterial::Rgb(_)))
        || !objects.is_empty()
    {
        crate::spectrum::uplift::prepare();
    }
}

/// Whether a scene's samples need footprints: something reads them.
fn footprints_wanted(
    observables: &[crate::film::Observable],
    disk: Option<&crate::disk::Disk>,
    sky: &crate::sky::Sky,
) -> bool {
    observables.iter().any(|o| o.needs_footprint())
        || disk.is_some_and(|d| d.filter == crate::config::Filter::Footprint && d.textured())
        || sky.filter() == Some(crate::config::Filter::Footprint)
}
