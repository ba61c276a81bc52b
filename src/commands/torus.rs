//! `torus`: the Fishbone-Moncrief torus as an iharm3d-format dump
//! (`blackhole::transfer::grmhd::torus`).

use crate::TorusArgs;
use anyhow::{Result, anyhow};
use blackhole::transfer::grmhd::torus::{TorusOptions, write_torus};

pub fn torus(a: &TorusArgs) -> Result<()> {
    let o = TorusOptions::parse(&a.metric, &a.grid, a.funnel).map_err(|e| anyhow!("--{e}"))?;
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
