//! Fitting a dump's mass unit to a measured flux density, as the EHT
//! normalises its simulation libraries (0.5 Jy at 230 GHz for M87*, 2.4 Jy
//! for Sgr A*): root finding in (ln m_unit, ln F) on whole renders.

/// One render of the search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Try {
    /// The mass unit tried (g).
    pub m_unit: f64,
    /// The total flux density it gave (Jy).
    pub jy: f64,
}

/// The search's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The last try: the fitted mass unit and its flux.
    pub m_unit: f64,
    pub jy: f64,
    /// d ln F / d ln m_unit between the last two tries.
    pub slope: f64,
    pub tries: Vec<Try>,
}

/// Most renders a fit takes.
pub const MAX_TRIES: usize = 40;

/// Finds m_unit giving `target` Jy within `tolerance` (relative), from
/// `start` (g): secant steps in (ln m, ln F) through the last two tries,
/// kept inside the bracket once the target is bracketed (halving it
/// where a step would leave it), the first step taking d ln F / d ln m = 2 (n_e ~ m, B ~ m^1/2: about 2 to
/// 3 for synchrotron at the EHT's frequencies). `flux(m)` renders at m;
/// `report` hears each try.
pub fn fit_m_unit(
    start: f64,
    target: f64,
    tolerance: f64,
    mut flux: impl FnMut(f64) -> anyhow::Result<f64>,
    mut report: impl FnMut(&Try),
) -> anyhow::Result<Fit> {
    let goal = target.ln();
    let mut tries: Vec<Try> = Vec::new();
    // Bracket in ln m: below and above the target.
    let mut lo: Option<(f64, f64)> = None;
    let mut hi: Option<(f64, f64)> = None;
    let mut x = start.ln();
    loop {
        let m = x.exp();
        let jy = flux(m)?;
        let t = Try { m_unit: m, jy };
        report(&t);
        tries.push(t);
        let y = if jy > 0.0 { jy.ln() } else { f64::NEG_INFINITY };
        let slope = slope_of(&tries);
        if (jy / target - 1.0).abs() <= tolerance && tries.len() >= 2 {
            return Ok(Fit {
                m_unit: m,
                jy,
                slope,
                tries,
            });
        }
        if tries.len() >= MAX_TRIES {
            anyhow::bail!(
                "medium.flux: no m_unit from {start:e} g gave {target} Jy within {tolerance:e} in {MAX_TRIES} renders (last: {m:e} g, {jy} Jy); the flux may not reach it (an optically thick source saturates)"
            );
        }
        if y < goal {
            lo = Some((x, y));
        } else {
            hi = Some((x, y));
        }
        // The secant through the last two tries (the slope 2 at first).
        let s = if slope.is_finite() && slope > 0.2 {
            slope
        } else {
            2.0
        };
        let secant = if y.is_finite() {
            x + (goal - y) / s
        } else {
            x + 5.0
        };
        x = match (lo, hi) {
            // Bracketed: the secant where it falls inside, else halving.
            (Some(l), Some(h)) => {
                let (a, b) = (l.0.min(h.0), l.0.max(h.0));
                if secant > a && secant < b {
                    secant
                } else {
                    0.5 * (a + b)
                }
            }
            // Not yet: steps of at most e^5.
            _ => x + (secant - x).clamp(-5.0, 5.0),
        };
    }
}

/// d ln F / d ln m between the last two tries (NaN before two).
fn slope_of(tries: &[Try]) -> f64 {
    match tries {
        [.., a, b] if a.jy > 0.0 && b.jy > 0.0 && a.m_unit != b.m_unit => {
            (b.jy / a.jy).ln() / (b.m_unit / a.m_unit).ln()
        }
        _ => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_is_fitted_in_a_few_tries_with_its_slope() {
        // F = 0.3 (m / 1e26)^2.4 Jy: the target 0.5 Jy at m = 1e26 (5/3)^(1/2.4).
        let f = |m: f64| 0.3 * (m / 1e26).powf(2.4);
        let want = 1e26 * (0.5f64 / 0.3).powf(1.0 / 2.4);
        let fit = fit_m_unit(1e24, 0.5, 1e-4, |m| Ok(f(m)), |_| {}).unwrap();
        assert!((fit.jy / 0.5 - 1.0).abs() <= 1e-4);
        assert!((fit.m_unit / want - 1.0).abs() < 1e-4 / 2.4 * 1.01);
        assert!((fit.slope - 2.4).abs() < 1e-9, "{}", fit.slope);
        assert!(fit.tries.len() <= 6, "{} tries", fit.tries.len());
    }

    #[test]
    fn a_flux_that_saturates_below_the_target_is_refused() {
        // F rises to 1 Jy and no further.
        let f = |m: f64| 1.0 - (-m / 1e26).exp();
        let e = fit_m_unit(1e25, 2.0, 1e-4, |m| Ok(f(m)), |_| {}).unwrap_err();
        assert!(e.to_string().contains("medium.flux"), "{e}");
    }

    #[test]
    fn a_flux_that_turns_over_is_still_fitted_on_its_rising_side() {
        // F = x e^(1 - x), x = m / 1e26: at most 1 Jy at x = 1.
        let f = |m: f64| {
            let x = m / 1e26;
            x * (1.0 - x).exp()
        };
        let fit = fit_m_unit(1e24, 0.5, 1e-5, |m| Ok(f(m)), |_| {}).unwrap();
        assert!((fit.jy / 0.5 - 1.0).abs() <= 1e-5);
        assert!(fit.m_unit < 1e26);
    }
}
