//! The star catalogue: CSV rows (`hip,ra_deg,dec_deg,vmag,bv`), parsed in
//! parallel, and each star as a point source in scene axes.
//!
//! The map from equatorial to scene axes: galactic coordinates with the
//! galactic centre (l = 0, b = 0) along +y, l = 90 deg along -x (so the sky
//! is seen unmirrored from inside) and the north galactic pole along +z.

use crate::spectrum::bv_to_kelvin;
use bytemuck::{Pod, Zeroable};
use glam::DVec3;
use rayon::prelude::*;

/// B-V used for the few catalogue stars without one (roughly solar).
pub const DEFAULT_BV: f64 = 0.65;

/// The header every catalogue starts with.
pub const HEADER: &str = "hip,ra_deg,dec_deg,vmag,bv";

/// One catalogue star.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Star {
    /// Hipparcos number.
    pub hip: u32,
    /// Right ascension (degrees, J2000).
    pub ra: f64,
    /// Declination (degrees, J2000).
    pub dec: f64,
    /// Visual magnitude.
    pub vmag: f64,
    /// B-V colour index, if known.
    pub bv: Option<f64>,
}

/// A star as a point source: five 32-bit words, the layout of the GPU's
/// copy (see the module docs of [`crate::stars`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PointStar {
    /// Unit direction towards the star, scene axes.
    pub dir: [f32; 3],
    /// Flux relative to a star of visual magnitude 0: 10^(-0.4 V).
    pub flux: f32,
    /// Blackbody temperature (K) from the B-V colour.
    pub kelvin: f32,
}

impl PointStar {
    /// The point source of a catalogue star.
    pub fn from_star(s: &Star) -> PointStar {
        let d = galactic_to_world(equatorial_to_galactic(s.ra, s.dec)).normalize();
        PointStar {
            dir: d.as_vec3().to_array(),
            flux: 10f64.powf(-0.4 * s.vmag) as f32,
            kelvin: star_kelvin(s.bv) as f32,
        }
    }

    /// Its direction in f64, renormalised (f32 components are unit length
    /// only to about 1e-7).
    #[inline]
    pub fn direction(&self) -> DVec3 {
        let d = DVec3::new(self.dir[0] as f64, self.dir[1] as f64, self.dir[2] as f64);
        d / d.length()
    }
}

/// A star's blackbody temperature (K) from its B-V colour, the catalogue's
/// gaps filled with [`DEFAULT_BV`] and the colour clamped to where the
/// B-V to temperature fit holds.
pub fn star_kelvin(bv: Option<f64>) -> f64 {
    bv_to_kelvin(bv.unwrap_or(DEFAULT_BV).clamp(-0.4, 2.0))
}

/// Equatorial (J2000) unit vector -> galactic unit vector (x to the
/// galactic centre, y to l = 90 deg, z to the north galactic pole).
pub fn equatorial_to_galactic(ra_deg: f64, dec_deg: f64) -> DVec3 {
    let (ra, dec) = (ra_deg.to_radians(), dec_deg.to_radians());
    let e = DVec3::new(dec.cos() * ra.cos(), dec.cos() * ra.sin(), dec.sin());
    EQUATORIAL_TO_GALACTIC * e
}

/// The rotation from equatorial (J2000) to galactic axes.
const EQUATORIAL_TO_GALACTIC: glam::DMat3 = glam::DMat3::from_cols_array(&[
    -0.054_875_560_4,
    0.494_109_427_9,
    -0.867_666_149_0,
    -0.873_437_090_2,
    -0.444_829_630_0,
    -0.198_076_373_4,
    -0.483_835_015_5,
    0.746_982_244_5,
    0.455_983_776_2,
]);

/// Galactic unit vector -> (right ascension, declination) in degrees,
/// J2000, right ascension in [0, 360).
pub fn galactic_to_equatorial(g: DVec3) -> (f64, f64) {
    let e = EQUATORIAL_TO_GALACTIC.transpose() * g;
    let ra = e.y.atan2(e.x).to_degrees().rem_euclid(360.0);
    (ra, e.z.clamp(-1.0, 1.0).asin().to_degrees())
}

/// Galactic unit vector -> scene direction (see the module docs).
pub fn galactic_to_world(g: DVec3) -> DVec3 {
    DVec3::new(-g.y, g.x, g.z)
}

/// Parses the catalogue CSV (`hip,ra_deg,dec_deg,vmag,bv`).
pub fn parse_catalogue(csv: &str) -> Result<Vec<Star>, String> {
    parse_rows(csv, |s| s)
}

/// Parses the catalogue CSV straight into point sources, without keeping
/// the rows (a third of the memory).
pub fn parse_point_stars(csv: &str) -> Result<Vec<PointStar>, String> {
    parse_rows(csv, |s| PointStar::from_star(&s))
}

/// Lines per parallel chunk, about: enough to keep each thread's start-up
/// negligible.
const CHUNK_BYTES: usize = 1 << 20;

/// Parses every row in parallel chunks of whole lines; the first bad row
/// in file order is the error.
fn parse_rows<T: Send>(csv: &str, map: impl Fn(Star) -> T + Sync) -> Result<Vec<T>, String> {
    // A byte-order mark (as spreadsheets save UTF-8) is no part of the
    // header.
    let csv = csv.strip_prefix('\u{feff}').unwrap_or(csv);
    let mut lines = csv.lines();
    let header = lines.next().ok_or("empty catalogue")?;
    if header.trim() != HEADER {
        return Err(format!("unexpected header {header:?}, expected {HEADER}"));
    }
    let body = csv.find('\n').map_or("", |k| &csv[k + 1..]);
    let chunks = line_chunks(body);
    // Line numbers: the header is line 1; each chunk starts after the
    // newlines of those before it.
    let newlines: Vec<usize> = chunks
        .par_iter()
        .map(|c| c.bytes().filter(|&b| b == b'\n').count())
        .collect();
    let firsts = newlines.iter().scan(2, |line, &n| {
        let first = *line;
        *line += n;
        Some(first)
    });
    let jobs: Vec<(usize, &str)> = firsts.zip(chunks).collect();
    let parsed: Vec<Result<Vec<T>, String>> = jobs
        .par_iter()
        .map(|&(first, chunk)| {
            chunk
                .lines()
                .enumerate()
                .filter(|(_, l)| !l.trim().is_empty())
                .map(|(i, l)| parse_row(l, first + i).map(&map))
                .collect()
        })
        .collect();
    let mut stars = Vec::with_capacity(parsed.iter().map(|p| p.as_ref().map_or(0, Vec::len)).sum());
    for p in parsed {
        stars.extend(p?);
    }
    // A header alone would give a black sky without a word.
    if stars.is_empty() {
        return Err(
            "has its header and no stars: expected a line hip,ra_deg,dec_deg,vmag,bv for each star"
                .into(),
        );
    }
    Ok(stars)
}

/// `text` cut after newlines into pieces of about [`CHUNK_BYTES`].
fn line_chunks(text: &str) -> Vec<&str> {
    let mut chunks = Vec::new();
    let mut rest = text;
    while rest.len() > CHUNK_BYTES {
        let cut = rest[CHUNK_BYTES..]
            .find('\n')
            .map_or(rest.len(), |k| CHUNK_BYTES + k + 1);
        let (a, b) = rest.split_at(cut);
        chunks.push(a);
        rest = b;
    }
    if !rest.is_empty() {
        chunks.push(rest);
    }
    chunks
}

/// One row, at line number `line` of the file.
fn parse_row(l: &str, line: usize) -> Result<Star, String> {
    let bad = || format!("line {line}: expected 5 fields hip,ra,dec,vmag,bv: {l:?}");
    let mut f = [""; 5];
    let mut k = 0;
    for field in l.split(',') {
        if k == 5 {
            return Err(bad());
        }
        f[k] = field.trim();
        k += 1;
    }
    if k != 5 {
        return Err(bad());
    }
    // Each number finite and where a star's can be.
    let num = |k: usize, name: &str, range: std::ops::RangeInclusive<f64>| {
        let v = f[k].parse::<f64>().unwrap_or(f64::NAN);
        if !range.contains(&v) {
            return Err(format!(
                "line {line}: {name} = {}: expected a number from {} to {}",
                f[k],
                range.start(),
                range.end()
            ));
        }
        Ok(v)
    };
    let ra = num(1, "ra_deg", 0.0..=360.0)?;
    Ok(Star {
        hip: f[0].parse().map_err(|_| {
            format!(
                "line {line}: hip = {}: expected the star's Hipparcos number, a whole number from 0 to {}",
                f[0],
                u32::MAX
            )
        })?,
        ra: if ra == 360.0 { 0.0 } else { ra },
        dec: num(2, "dec_deg", -90.0..=90.0)?,
        // The Sun is -26.7; the faintest catalogued stars about 21.
        vmag: num(3, "vmag", -30.0..=30.0)?,
        // Stellar B-V runs from about -0.4 to 5.5 (the reddest carbon
        // stars of the shipped catalogue).
        bv: if f[4].is_empty() {
            None
        } else {
            Some(num(4, "bv", -1.0..=10.0)?)
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn galactic_centre_and_pole() {
        // Sgr A*: RA 266.405, Dec -28.936 -> l = 0, b = 0.
        let g = equatorial_to_galactic(266.405, -28.936);
        assert!((g - DVec3::X).length() < 2e-3, "{g}");
        // North galactic pole: RA 192.859, Dec 27.128.
        let g = equatorial_to_galactic(192.859, 27.128);
        assert!((g - DVec3::Z).length() < 2e-3, "{g}");
        assert_eq!(galactic_to_world(DVec3::X), DVec3::Y);
        // And back.
        let (ra, dec) = galactic_to_equatorial(equatorial_to_galactic(101.2872, -16.7161));
        assert!((ra - 101.2872).abs() < 1e-7 && (dec + 16.7161).abs() < 1e-7);
    }

    #[test]
    fn catalogue_parses_and_rejects_garbage() {
        let s = parse_catalogue(
            "hip,ra_deg,dec_deg,vmag,bv\n32349,101.2872,-16.7161,-1.44,0.01\n1,2,3,4,\n",
        )
        .unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].bv, Some(0.01));
        assert_eq!(s[1].bv, None);
        assert!(parse_catalogue("hip,ra\n").is_err());
        assert_eq!(parse_catalogue("").unwrap_err(), "empty catalogue");
        assert!(parse_catalogue("hip,ra_deg,dec_deg,vmag,bv\n\n  \n").is_err());
        assert!(parse_catalogue("hip,ra_deg,dec_deg,vmag,bv\n1,2,x,4,5\n").is_err());
        // A byte-order mark before the header is read past.
        let s = parse_catalogue("\u{feff}hip,ra_deg,dec_deg,vmag,bv\n1,2,3,4,0.5\n").unwrap();
        assert_eq!(s.len(), 1);
        // Numbers that are no star's, named with their line.
        for (row, needle) in [
            ("1,nan,3,4,0.5", "line 3: ra_deg = nan"),
            ("1,2,999,4,0.5", "line 3: dec_deg = 999"),
            ("1,2,3,-1e308,0.5", "line 3: vmag = -1e308"),
            ("1,2,3,4,1e308", "line 3: bv = 1e308"),
            ("1,2,3,inf,0.5", "line 3: vmag = inf"),
            ("1,2,3,4", "line 3: expected 5 fields"),
            ("1,2,3,4,5,6", "line 3: expected 5 fields"),
            (
                "-1,2,3,4,5",
                "line 3: hip = -1: expected the star's Hipparcos number",
            ),
            ("x,2,3,4,5", "line 3: hip = x: expected"),
            (
                "1,ra,3,4,5",
                "line 3: ra_deg = ra: expected a number from 0 to 360",
            ),
        ] {
            let text = format!("hip,ra_deg,dec_deg,vmag,bv\n1,2,3,4,0.5\n{row}\n");
            let e = parse_catalogue(&text).unwrap_err();
            assert!(e.contains(needle), "{row}: {e}");
        }
    }

    #[test]
    fn errors_name_the_first_bad_line_across_chunks() {
        // Rows over several parallel chunks, blank lines and CRLF counted
        // as lines: the first bad row in the file is the one named.
        let mut text = String::from("hip,ra_deg,dec_deg,vmag,bv\r\n");
        let rows = 3 * CHUNK_BYTES / 20;
        for i in 0..rows {
            if i % 1000 == 7 {
                text.push_str("\r\n");
            }
            text.push_str("1,10.5,20.25,5.5,0.5\r\n");
        }
        let n = parse_catalogue(&text).unwrap().len();
        assert_eq!(n, rows);
        let lines: Vec<&str> = text.lines().collect();
        let (early, late) = (lines.len() / 2 + 3, lines.len() - 2);
        let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        bad[late] = "1,2,3,99,0.5".into();
        bad[early] = "1,2,-91,5,0.5".into();
        let e = parse_catalogue(&bad.join("\n")).unwrap_err();
        assert!(
            e.starts_with(&format!("line {}: dec_deg = -91", early + 1)),
            "{e}"
        );
    }

    #[test]
    fn point_stars_carry_flux_and_temperature() {
        let text = "hip,ra_deg,dec_deg,vmag,bv\n32349,101.2872,-16.7161,-1.44,0.01\n7,0,90,5,\n";
        let p = parse_point_stars(text).unwrap();
        let sirius = galactic_to_world(equatorial_to_galactic(101.2872, -16.7161));
        assert!((p[0].direction() - sirius).length() < 1e-7);
        assert!((p[0].flux as f64 / 10f64.powf(0.576) - 1.0).abs() < 1e-6);
        assert_eq!(p[0].kelvin, bv_to_kelvin(0.01) as f32);
        assert!((p[1].flux - 0.01).abs() < 1e-8);
        assert_eq!(p[1].kelvin, bv_to_kelvin(DEFAULT_BV) as f32);
        assert_eq!(std::mem::size_of::<PointStar>(), 20);
    }
}
