//! The shipped Slurm job scripts on a real Slurm: a still as a job array of
//! tiles and a merge that depends on it, an animation as runs of frames
//! and its video; results byte for byte those of single runs. The work is
//! in `validation/slurm/harness.sh` (which a developer can run alone);
//! it starts a private single-node Slurm when none answers (as root) and
//! stops what it started. Without Slurm and munge the test prints why and
//! passes, unless `CI` is set.

mod common;

use std::process::Command;

/// Whether Slurm answers or can be started here.
fn slurm() -> Result<(), String> {
    for t in ["sbatch", "squeue", "sinfo", "slurmctld", "slurmd", "munged"] {
        let found = Command::new("sh")
            .args(["-c", &format!("command -v {t}")])
            .output()
            .is_ok_and(|o| o.status.success());
        if !found {
            return Err(format!(
                "{t} is not installed (apt-get install slurm-wlm munge)"
            ));
        }
    }
    let running = Command::new("sinfo")
        .arg("-h")
        .output()
        .is_ok_and(|o| o.status.success());
    let root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !running && !root {
        return Err("no Slurm answers and starting one needs root".into());
    }
    Ok(())
}

#[test]
fn job_arrays_of_tiles_and_frames_give_the_single_run_bytes() {
    if !common::available(slurm()) {
        return;
    }
    let out = Command::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/validation/slurm/harness.sh"
    ))
    .arg(env!("CARGO_BIN_EXE_blackhole"))
    .output()
    .unwrap();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{log}");
    assert!(out.status.success(), "{log}");
    assert!(log.contains("slurm harness passed"), "{log}");
}
