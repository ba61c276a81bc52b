//! `torus`: the Fishbone-Moncrief torus as an iharm3d-format dump
//! (`blackhole::transfer::grmhd::torus`).

use crate::TorusArgs;
use anyhow::{Result, bail};
use blackhole::transfer::grmhd::torus::{Metric, TorusOptions, write_torus};

/// "N1xN2xN3" as three cell counts.
fn grid(text: &str) -> Result<[usize; 3]> {
    let parts: Vec<Option<usize>> = text.split('x').map(|p| p.trim().parse().ok()).collect();
    match parts.as_slice() {
        [Some(a), Some(b), Some(c)] if *a >= 8 && *b >= 4 && *c >= 1 && a * b * c <= 1 << 28 => {
            Ok([*a, *b, *c])
        }
        _ => bail!(
            "--grid {text:?}: expected N1xN2xN3, cell counts along the radius (at least 8), the polar angle (at least 4) and the azimuth (at least 1), such as 128x64x4"
        ),
    }
}

pub fn torus(a: &TorusArgs) -> Result<()> {
    let o = TorusOptions {
        metric: if a.metric == "fmks" {
            Metric::Fmks
        } else {
            Metric::Mks
        },
        n: grid(&a.grid)?,
        funnel: a.funnel,
    };
    let h = write_torus(&a.out, &o)?;
    if !a.quiet {
        println!(
            "wrote {}: Fishbone-Moncrief torus, {} {}x{}x{}, a {}, r {:.4} to {} M{}",
            a.out.display(),
            h.metric,
            h.n[0],
            h.n[1],
            h.n[2],
            h.a,
            h.r_in,
            h.r_out,
            if a.funnel {
                ", with a magnetised funnel"
            } else {
                ""
            }
        );
    }
    Ok(())
}
