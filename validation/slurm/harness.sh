#!/bin/bash
# Runs the shipped Slurm job scripts (configs/slurm/) on a real Slurm and
# checks their results against single runs:
#   a still as 4 tiles + merge      -> the same PNG and EXR bytes as `render`
#   one failed task run again alone, and the array resubmitted (complete
#   tiles kept)                     -> the same PNG
#   an observed scene as 3 tiles    -> the same PNG, EXR and spectrum CSV
#   an animation as 3 runs + video  -> the same frame bytes as `animate`, and the video
#   a GRMHD image library (2 snapshots x 2 inclinations x 2 R-high) and
#   its summary table                -> the same image bytes as `render`
# Uses the Slurm that answers (sinfo) if there is one; else starts a
# private single-node one (configuration, spool, logs and pid files in a
# scratch folder; munged from the system if none runs) and stops the
# daemons it started, by their pid files, however it ends. Starting
# daemons needs root and Debian's slurm-wlm and munge.
#
#   validation/slurm/harness.sh [--bench] [BINARY]
# --bench instead times 1, 2 and 4 array tasks on one render, and the merge.
# BINARY defaults to target/release/blackhole. Exit status 0 when every
# check passes.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
bench=0
if [ "${1:-}" = --bench ]; then bench=1; shift; fi
bin=$(realpath "${1:-target/release/blackhole}")
[ -x "$bin" ] || { echo "no binary $bin: cargo build --release first" >&2; exit 1; }
export BLACKHOLE=$bin
for t in sbatch squeue sinfo scontrol slurmctld slurmd munged munge unmunge; do
  command -v "$t" >/dev/null || { echo "$t is missing: apt-get install slurm-wlm munge" >&2; exit 1; }
done

work=$(mktemp -d /tmp/blackhole-slurm.XXXXXX)
started=()
alive() { [ -r "/proc/$1/status" ] && ! grep -q '^State:[[:space:]]*Z' "/proc/$1/status"; }
stop() {
  local f p i
  for f in "${started[@]}"; do
    [ -s "$f" ] || continue
    p=$(cat "$f")
    kill -TERM "$p" 2>/dev/null || true
    for i in $(seq 300); do alive "$p" || break; sleep 0.1; done
    alive "$p" && kill -KILL "$p" 2>/dev/null || true
  done
  rm -rf "$work"
}
trap stop EXIT

# --- Slurm: the running one, or a private one
if ! sinfo -h >/dev/null 2>&1; then
  [ "$(id -u)" -eq 0 ] || { echo "no Slurm answers and starting one needs root" >&2; exit 1; }
  if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    if [ ! -s /etc/munge/munge.key ]; then
      runuser -u munge -- mungekey --create --keyfile=/etc/munge/munge.key
    fi
    chown munge:munge /etc/munge/munge.key
    chmod 0400 /etc/munge/munge.key
    install -d -o munge -g munge -m 0755 /run/munge
    runuser -u munge -- /usr/sbin/munged
    started+=(/run/munge/munged.pid)
    for i in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
  fi
  s=$work/slurm
  mkdir -p "$s/ctld" "$s/d" "$s/log"
  host=$(hostname -s)
  mem=$(free -m | awk '/^Mem:/ { print int($2 * 0.9) }')
  cat > "$s/slurm.conf" <<CONF
ClusterName=blackhole
SlurmctldHost=${host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MailProg=/bin/true
StateSaveLocation=$s/ctld
SlurmdSpoolDir=$s/d
SlurmctldPidFile=$s/slurmctld.pid
SlurmdPidFile=$s/slurmd.pid
SlurmctldLogFile=$s/log/slurmctld.log
SlurmdLogFile=$s/log/slurmd.log
NodeName=${host} NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=${mem} State=UNKNOWN
PartitionName=debug Nodes=${host} Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$s/slurm.conf
  started=("$s/slurmd.pid" "$s/slurmctld.pid" "${started[@]}")
  /usr/sbin/slurmctld -c -f "$SLURM_CONF"
  /usr/sbin/slurmd -f "$SLURM_CONF"
  for i in $(seq 150); do
    [ "$(sinfo -h -o %t 2>/dev/null)" = idle ] && break
    sleep 0.2
  done
  [ "$(sinfo -h -o %t 2>/dev/null)" = idle ] || {
    echo "the private Slurm did not come up:" >&2
    tail -n 20 "$s/log/"*.log >&2
    exit 1
  }
  echo "started a private Slurm (pid files in $s)"
fi

# Waits, at most $2 seconds, until none of jobs $1 (comma list) is queued;
# fails if one did not complete.
wait_jobs() {
  local i
  for i in $(seq $(($2 * 5))); do
    [ -z "$(squeue -h -j "$1" 2>/dev/null)" ] && break
    sleep 0.2
  done
  [ -z "$(squeue -h -j "$1" 2>/dev/null)" ] || { echo "jobs $1 still queued after $2 s" >&2; squeue >&2; return 1; }
  local bad
  bad=$(scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | grep -v COMPLETED || true)
  if [ -n "$bad" ]; then
    echo "jobs $1 ended badly: $bad" >&2
    cat "$work"/logs/* >&2 || true
    return 1
  fi
}

submit() { # kind n config args... -> "array follow-up"
  BLACKHOLE_LOGS=$work/logs "$root/configs/slurm/submit.sh" "$@"
}

now() { date +%s.%N; }

if [ $bench -eq 1 ]; then
  still=(configs/side.toml --set image.width=1920 --set image.height=1080 --set image.samples=4)
  echo "render: ${still[*]}"
  t0=$(now)
  "$bin" render -q "${still[@]}" --set "image.png=$work/one/side.png" --threads 1
  echo "one process, 1 thread: $(echo "$(now) - $t0" | bc) s"
  for n in 1 2 4; do
    t0=$(now)
    read -r a b < <(submit tiles $n "${still[@]}" --set "image.png=$work/n$n/side.png")
    wait_jobs "$a,$b" 900
    echo "$n array task(s) + merge, submit to merged: $(echo "$(now) - $t0" | bc) s"
  done
  t0=$(now)
  "$bin" merge -q "${still[@]}" --set "image.png=$work/n4/side.png"
  echo "merge of 4 tiles alone: $(echo "$(now) - $t0" | bc) s"
  cmp "$work/one/side.png" "$work/n4/side.png"
  exit 0
fi

# --- a still: 4 tiles and the merge against one render
still=(configs/spectral_side.toml --set image.width=160 --set image.height=90 --set image.samples=4
  --set spectral.exr_layers=true)
"$bin" render -q "${still[@]}" --set "image.png=$work/one/still.png"
read -r a b < <(submit tiles 4 "${still[@]}" --set "image.png=$work/tiles/still.png")
echo "tiles: array job $a, merge job $b"
wait_jobs "$a,$b" 300
ls "$work/tiles"
cmp "$work/one/still.png" "$work/tiles/still.png"
cmp "$work/one/still.exr" "$work/tiles/still.exr"
echo "merged still: PNG and EXR identical to one render"

# --- an observed scene (radiative transfer, janskys per pixel): 3 tiles
# and the merge against one render, the spectrum's table too
obs=(configs/sgra.toml --set image.width=48 --set image.height=48 --set image.samples=1
  --set "observe.frequency=[86e9, 230e9]")
"$bin" render -q "${obs[@]}" --set "image.png=$work/one/sgra.png" --set "image.exr=$work/one/sgra.exr"
read -r a b < <(submit tiles 3 "${obs[@]}" --set "image.png=$work/tiles/sgra.png" \
  --set "image.exr=$work/tiles/sgra.exr")
echo "observed tiles: array job $a, merge job $b"
wait_jobs "$a,$b" 300
for f in sgra.png sgra.exr sgra.spectrum.csv; do cmp "$work/one/$f" "$work/tiles/$f"; done
echo "merged observed scene: PNG, EXR and spectrum identical to one render"

# --- a failed task runs again alone, with the N of its array; the whole
# array submitted again keeps the tiles that are complete
out=(--set "image.png=$work/tiles/still.png")
rm "$work/tiles/still.tile-2-of-4.exr" "$work/tiles/still.png" "$work/tiles/still.exr"
kept=$(stat -c %y "$work"/tiles/still.tile-{0,1,3}-of-4.exr)
a=$(sbatch --parsable --array=2 --output="$work/logs/%x-%A_%a.out" \
  "$root/configs/slurm/tiles.sbatch" 4 "${still[@]}" "${out[@]}")
wait_jobs "${a%%;*}" 300
test -s "$work/tiles/still.tile-2-of-4.exr"
read -r a b < <(submit tiles 4 "${still[@]}" "${out[@]}")
wait_jobs "$a,$b" 300
[ "$kept" = "$(stat -c %y "$work"/tiles/still.tile-{0,1,3}-of-4.exr)" ] || {
  echo "resubmitting the array rendered complete tiles again" >&2
  exit 1
}
cmp "$work/one/still.png" "$work/tiles/still.png"
echo "rerun of task 2 alone and a resubmitted array: the same PNG"
# A task beyond N is refused by name.
a=$(sbatch --parsable --array=4 --output="$work/logs/beyond-%A_%a.out" \
  "$root/configs/slurm/tiles.sbatch" 4 "${still[@]}" "${out[@]}")
wait_jobs "${a%%;*}" 300 2>/dev/null && { echo "task 4 of 4 ran" >&2; exit 1; }
grep -q "array task 4 is not a tile of 4" "$work"/logs/beyond-* || {
  cat "$work"/logs/beyond-* >&2
  exit 1
}
# submit.sh names a binary it cannot find.
if err=$(BLACKHOLE=no-such-blackhole "$root/configs/slurm/submit.sh" tiles 2 "${still[@]}" 2>&1); then
  echo "submit.sh ran without a binary" >&2
  exit 1
fi
[[ $err == *"no no-such-blackhole on the PATH"* ]] || { echo "submit.sh said: $err" >&2; exit 1; }

# --- a GRMHD image library: 2 snapshots x 2 inclinations x 2 R-high as
# an array of 8 images, then the summary table; each image the bytes of
# its single render
"$bin" torus "$work/lib/a.h5" --grid 32x16x4 -q
"$bin" torus "$work/lib/b.h5" --grid 32x16x4 --metric fmks -q
cat > "$work/lib/library.txt" <<LIB
dumps = $work/lib/a.h5 $work/lib/b.h5
inclinations = 17 163
r_high = 1 10   # T_i/T_e at high beta
camera_m = 9.1576e16
out = $work/lib/images
LIB
torus=(configs/m87_torus.toml --unset medium.torus --unset medium.flux --set image.width=16
  --set image.height=16 --set medium.m_unit=4e29 --set medium.r_low=3)
read -r a b < <(submit library "$work/lib/library.txt" "${torus[@]}")
echo "library: array job $a, summary job $b"
wait_jobs "$a,$b" 300
rows=$(tail -n +2 "$work/lib/images/summary.csv" | wc -l)
[ "$rows" -eq 8 ] || { echo "the library's summary has $rows rows, expected 8" >&2; cat "$work/lib/images/summary.csv" >&2; exit 1; }
"$bin" render -q "${torus[@]}" --set "medium.dump=$work/lib/b.h5" --set medium.r_high=10 \
  --set "camera.position=$(awk 'BEGIN { a = 163 * atan2(0, -1) / 180; printf "[%.17e, 0.0, %.17e]", 9.1576e16 * sin(a), 9.1576e16 * cos(a) }')" \
  --set "image.png=$work/one/b_i163_rh10.png" --set "image.exr=$work/one/b_i163_rh10.exr"
for f in png exr spectrum.csv; do cmp "$work/one/b_i163_rh10.$f" "$work/lib/images/b_i163_rh10.$f"; done
grep -q "^$work/lib/b.h5,163,10,2.3e11,$(tail -n 1 "$work/one/b_i163_rh10.spectrum.csv" | cut -d, -f2)\$" \
  "$work/lib/images/summary.csv" || { echo "summary.csv lacks b_i163_rh10's flux" >&2; cat "$work/lib/images/summary.csv" >&2; exit 1; }
echo "GRMHD library: 8 images, summary.csv, an image identical to its single render"

# --- an animation: 3 runs of frames and the video against one run
anim=(configs/orbit.toml --set image.width=64 --set image.height=36 --set animation.frames=6)
"$bin" animate -q "${anim[@]}" --set "image.png=$work/one/orbit/orbit.png" \
  --set "animation.video=$work/one/orbit.gif"
read -r a b < <(submit frames 3 "${anim[@]}" --set "image.png=$work/frames/orbit/orbit.png" \
  --set "animation.video=$work/frames/orbit.gif")
echo "frames: array job $a, video job $b"
wait_jobs "$a,$b" 300
for k in 0 1 2 3 4 5; do
  f=$(printf 'orbit_%05d.png' "$k")
  cmp "$work/one/orbit/$f" "$work/frames/orbit/$f"
done
cmp "$work/one/orbit.gif" "$work/frames/orbit.gif"
echo "frames and video: identical to one run"
echo "slurm harness passed"
