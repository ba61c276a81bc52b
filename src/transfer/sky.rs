//! Where an observed image lies on Earth's sky, as a distant observer sees
//! it: the size of its pixels, the source's position and name, its
//! frequencies. The FITS files (ehtim's layout), Python's WCS and the EXR's
//! header all take them from here, so that they agree.
//!
//! The image is the camera's view of the hole: its up is North and its
//! left East, as on the sky (a telescope's view, not a mirror's); its
//! angles are the camera's times r_cam / D, the camera's distance from
//! the hole over the source's.

use crate::config::SceneConfig;
use crate::units::PARSEC as PARSEC_M;

/// The Modified Julian Date written where a scene gives none: J2000.0's
/// day (2000 January 1), ehtim's own default.
pub const DEFAULT_MJD: f64 = 51544.0;

/// An observed image's place on the sky.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyFrame {
    /// A pixel's side at the image's centre as Earth sees it (degrees).
    pub pixel_deg: f64,
    /// The source's right ascension and declination (degrees, J2000).
    pub ra: f64,
    pub dec: f64,
    /// Its distance (pc).
    pub distance_pc: f64,
    /// The observed frequencies (Hz).
    pub frequencies: Vec<f64>,
    /// Its name (`observe.source`, else the image's file name).
    pub source: String,
    /// The date of the observation (MJD).
    pub mjd: f64,
    /// The image's size in pixels (the whole image's, of a tile too).
    pub width: u32,
    pub height: u32,
}

/// A FITS header value.
#[derive(Clone, Debug, PartialEq)]
pub enum Card {
    Text(&'static str),
    Number(f64),
}

impl SkyFrame {
    /// The sky frame of an observed scene (None for others).
    pub fn of(cfg: &SceneConfig) -> Option<SkyFrame> {
        let o = cfg.observe.as_ref()?;
        let camera_pc = glam::DVec3::from_array(cfg.camera.position).length() / PARSEC_M;
        // The pinhole's pixel at the centre: 2 tan(fov / 2) / height rad.
        let half = (cfg.camera.fov.to_radians() * 0.5).tan();
        let pixel = 2.0 * half / cfg.image.height as f64 * camera_pc / o.distance.pc;
        let source = o.source.clone().unwrap_or_else(|| {
            cfg.image
                .png
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
        Some(SkyFrame {
            pixel_deg: pixel.to_degrees(),
            ra: o.ra.unwrap_or(0.0),
            dec: o.dec.unwrap_or(0.0),
            distance_pc: o.distance.pc,
            frequencies: o.frequency.list(),
            source,
            mjd: o.mjd.unwrap_or(DEFAULT_MJD),
            width: cfg.image.width,
            height: cfg.image.height,
        })
    }

    /// A pixel's side in micro-arcseconds.
    pub fn pixel_uas(&self) -> f64 {
        self.pixel_deg * 3.6e9
    }

    /// The celestial WCS of the image's rows `rows` (a tile's band, or all)
    /// stored bottom-up, as ehtim writes it: RA---SIN / DEC--SIN in
    /// degrees about the source, East to the left (CDELT1 < 0), the
    /// reference pixel the image's centre.
    pub fn wcs(&self, rows: std::ops::Range<u32>) -> Vec<(&'static str, Card)> {
        let (w, h) = (self.width as f64, self.height as f64);
        let rows_below = h - rows.end as f64;
        vec![
            ("CTYPE1", Card::Text("RA---SIN")),
            ("CTYPE2", Card::Text("DEC--SIN")),
            ("CUNIT1", Card::Text("deg")),
            ("CUNIT2", Card::Text("deg")),
            ("CRVAL1", Card::Number(self.ra)),
            ("CRVAL2", Card::Number(self.dec)),
            ("CDELT1", Card::Number(-self.pixel_deg)),
            ("CDELT2", Card::Number(self.pixel_deg)),
            ("CRPIX1", Card::Number(w / 2.0 + 0.5)),
            ("CRPIX2", Card::Number(h / 2.0 + 0.5 - rows_below)),
        ]
    }

    /// What the EXR's header says of it, one `key=value` a line in the
    /// layer's comments: the flux channels' unit and pixel scale, the
    /// distance, the frequencies and the source.
    pub fn exr_tags(&self) -> Vec<(&'static str, String)> {
        let hz: Vec<String> = self.frequencies.iter().map(|f| format!("{f:e}")).collect();
        vec![
            ("observe.unit", "Jy/pixel".into()),
            ("observe.pixel_uas", format!("{:e}", self.pixel_uas())),
            ("observe.distance_pc", format!("{:e}", self.distance_pc)),
            ("observe.frequencies_hz", hz.join(",")),
            ("observe.source", self.source.clone()),
            ("observe.ra_deg", format!("{:e}", self.ra)),
            ("observe.dec_deg", format!("{:e}", self.dec)),
            ("observe.mjd", format!("{:e}", self.mjd)),
        ]
    }
}
