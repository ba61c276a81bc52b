//! Physical quantities as a scene writes them: a bare number in the key's
//! own unit (Hz, pc), or a string with a unit (`"230 GHz"`, `"8.178 kpc"`,
//! `"1e15Hz"`), as radio astronomers write them.

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use std::fmt;

/// Frequency units and their size in Hz.
pub const FREQUENCY_UNITS: [(&str, f64); 7] = [
    ("Hz", 1.0),
    ("kHz", 1e3),
    ("MHz", 1e6),
    ("GHz", 1e9),
    ("THz", 1e12),
    ("PHz", 1e15),
    ("EHz", 1e18),
];

use crate::units::PARSEC as PARSEC_M;

/// Distance units and their size in parsecs (the astronomical unit and the
/// Julian light year of the IAU).
pub const DISTANCE_UNITS: [(&str, f64); 8] = [
    ("pc", 1.0),
    ("kpc", 1e3),
    ("Mpc", 1e6),
    ("Gpc", 1e9),
    ("ly", 9_460_730_472_580_800.0 / PARSEC_M),
    ("au", 149_597_870_700.0 / PARSEC_M),
    ("km", 1e3 / PARSEC_M),
    ("m", 1.0 / PARSEC_M),
];

/// Flux density units and their size in janskys.
pub const FLUX_UNITS: [(&str, f64); 4] = [("Jy", 1.0), ("mJy", 1e-3), ("uJy", 1e-6), ("kJy", 1e3)];

/// A flux density (Jy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flux {
    pub jy: f64,
}

const FLUX: Kind = Kind {
    name: "flux density",
    units: &FLUX_UNITS,
};

impl<'de> Deserialize<'de> for Flux {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (jy, _) = d.deserialize_any(QuantityVisitor(&FLUX))?;
        Ok(Flux { jy })
    }
}

/// A frequency (Hz), and whether the file gave it as a bare number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frequency {
    pub hz: f64,
    pub bare: bool,
}

/// A distance (pc), and whether the file gave it as a bare number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distance {
    pub pc: f64,
    pub bare: bool,
}

/// What a quantity is and the units it takes.
struct Kind {
    name: &'static str,
    units: &'static [(&'static str, f64)],
}

const FREQUENCY: Kind = Kind {
    name: "frequency",
    units: &FREQUENCY_UNITS,
};

const DISTANCE: Kind = Kind {
    name: "distance",
    units: &DISTANCE_UNITS,
};

impl Kind {
    /// What the key takes, for messages.
    fn expected(&self) -> String {
        let names: Vec<&str> = self.units.iter().map(|u| u.0).collect();
        format!(
            "a {} as a number in {} or a string with a unit ({})",
            self.name,
            self.units[0].0,
            names.join(", ")
        )
    }

    /// `text` ("230 GHz", "8.178kpc") in the base unit.
    fn parse(&self, text: &str) -> Result<f64, String> {
        let t = text.trim();
        // The longest leading number whose rest is a unit.
        let split = (1..=t.len())
            .rev()
            .filter(|&i| t.is_char_boundary(i))
            .find_map(|i| {
                let value: f64 = t[..i].trim().parse().ok()?;
                Some((value, t[i..].trim()))
            });
        let Some((value, unit)) = split else {
            return Err(format!("\"{text}\" is not {}", self.expected()));
        };
        if unit.is_empty() {
            return Ok(value);
        }
        if let Some(&(_, size)) = self.units.iter().find(|u| u.0 == unit) {
            return Ok(value * size);
        }
        let near = self
            .units
            .iter()
            .find(|u| u.0.eq_ignore_ascii_case(unit))
            .map(|u| format!(" (\"{}\"?)", u.0))
            .unwrap_or_default();
        Err(format!(
            "\"{text}\": unknown unit \"{unit}\"{near}; expected {}",
            self.expected()
        ))
    }
}

/// A quantity of `kind` from a number (its base unit) or a string with a
/// unit: (the value, whether it was bare).
struct QuantityVisitor(&'static Kind);

impl Visitor<'_> for QuantityVisitor {
    type Value = (f64, bool);

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(&self.0.expected())
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        Ok((v, true))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        Ok((v as f64, true))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        Ok((v as f64, true))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
        self.0.parse(v).map(|x| (x, false)).map_err(E::custom)
    }
}

impl<'de> Deserialize<'de> for Frequency {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (hz, bare) = d.deserialize_any(QuantityVisitor(&FREQUENCY))?;
        Ok(Frequency { hz, bare })
    }
}

impl<'de> Deserialize<'de> for Distance {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (pc, bare) = d.deserialize_any(QuantityVisitor(&DISTANCE))?;
        Ok(Distance { pc, bare })
    }
}

/// One frequency or several (`observe.frequency`), each a number in Hz or
/// a string with a unit.
#[derive(Clone, Debug, PartialEq)]
pub enum Frequencies {
    One(Frequency),
    Many(Vec<Frequency>),
}

impl Frequencies {
    /// Every frequency (Hz), in the file's order.
    pub fn list(&self) -> Vec<f64> {
        self.each().iter().map(|f| f.hz).collect()
    }

    /// Every frequency as written.
    pub fn each(&self) -> Vec<Frequency> {
        match self {
            Frequencies::One(f) => vec![*f],
            Frequencies::Many(v) => v.clone(),
        }
    }
}

struct FrequenciesVisitor;

impl<'de> Visitor<'de> for FrequenciesVisitor {
    type Value = Frequencies;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}, or a list of them", FREQUENCY.expected())
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        Ok(Frequencies::One(Frequency { hz: v, bare: true }))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        self.visit_f64(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
        let hz = FREQUENCY.parse(v).map_err(E::custom)?;
        Ok(Frequencies::One(Frequency { hz, bare: false }))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut v = Vec::new();
        while let Some(f) = seq.next_element::<Frequency>()? {
            v.push(f);
        }
        Ok(Frequencies::Many(v))
    }
}

impl<'de> Deserialize<'de> for Frequencies {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(FrequenciesVisitor)
    }
}

/// `hz` in the unit that keeps its number between 1 and 1000 (Hz to EHz),
/// to 6 significant digits, trailing zeros dropped: "230 GHz", "1 PHz",
/// "345.5 GHz".
pub fn frequency_text(hz: f64) -> String {
    quantity_text(hz, &FREQUENCY_UNITS[..6])
}

/// `pc` in pc, kpc, Mpc or Gpc as [`frequency_text`] does: "7.778 kpc".
pub fn distance_text(pc: f64) -> String {
    quantity_text(pc, &DISTANCE_UNITS[..4])
}

/// `x` in the largest of `units` (ascending) it is at least one of.
fn quantity_text(x: f64, units: &[(&str, f64)]) -> String {
    if !x.is_finite() || x <= 0.0 {
        return format!("{x} {}", units[0].0);
    }
    let (name, size) = units
        .iter()
        .rev()
        .find(|u| x >= u.1 * (1.0 - 1e-12))
        .unwrap_or(&units[0]);
    let v = x / size;
    let digits = (5 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.digits$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    format!("{text} {name}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_as_written_give_hz_and_parsecs() {
        for (text, hz) in [
            ("230 GHz", 230e9),
            ("230GHz", 230e9),
            (" 1e15 Hz ", 1e15),
            ("3.2e16Hz", 3.2e16),
            ("86 GHz", 86e9),
            ("1 THz", 1e12),
            ("1.5 MHz", 1.5e6),
            ("230e9", 230e9),
        ] {
            assert_eq!(FREQUENCY.parse(text), Ok(hz), "{text}");
        }
        for (text, pc) in [
            ("8.178 kpc", 8178.0),
            ("16.8 Mpc", 16.8e6),
            ("7778", 7778.0),
            ("1 pc", 1.0),
            ("1 ly", 0.306_601_393_785_550_6),
            ("206264.80624709636 au", 1.0),
        ] {
            let got = DISTANCE.parse(text).unwrap();
            assert!((got / pc - 1.0).abs() < 1e-15, "{text}: {got}");
        }
    }

    #[test]
    fn unknown_units_are_named_with_the_ones_taken() {
        let e = FREQUENCY.parse("230 Ghz").unwrap_err();
        assert!(
            e.contains("unknown unit \"Ghz\" (\"GHz\"?)") && e.contains("THz"),
            "{e}"
        );
        let e = DISTANCE.parse("8 parsec").unwrap_err();
        assert!(
            e.contains("unknown unit \"parsec\"") && e.contains("kpc"),
            "{e}"
        );
        let e = FREQUENCY.parse("GHz").unwrap_err();
        assert!(e.contains("is not a frequency"), "{e}");
    }

    #[test]
    fn frequencies_read_in_a_unit_that_suits_them() {
        for (hz, text) in [
            (230e9, "230 GHz"),
            (345.5e9, "345.5 GHz"),
            (1e15, "1 PHz"),
            (3.2e16, "32 PHz"),
            (999e9, "999 GHz"),
            (1e12, "1 THz"),
            (2.4e9, "2.4 GHz"),
            (0.5, "0.5 Hz"),
            (123_456_789.0, "123.457 MHz"),
        ] {
            assert_eq!(frequency_text(hz), text);
        }
        assert_eq!(distance_text(8178.0), "8.178 kpc");
        assert_eq!(distance_text(16.8e6), "16.8 Mpc");
        assert_eq!(distance_text(0.3), "0.3 pc");
    }
}
