#!/usr/bin/env bash
# The README's test command as on a machine without the optional programs:
#   validation/without_extras.sh
# runs `cargo test --release` with `CI` unset, ffmpeg, Xvfb, xdotool,
# ImageMagick, Slurm, munge, chromium and node hidden from the PATH and no
# Vulkan driver (so no lavapipe), and checks that it passes and that each
# test needing a missing program says `skipped: ...` for it.
set -euo pipefail
cd "$(dirname "$0")/.."
hidden=" ffmpeg ffprobe Xvfb xvfb-run xdotool import convert sbatch srun sinfo squeue scontrol
  slurmctld slurmd munged chromium chromium-browser node npm "
hidden=$(echo $hidden)
shadow=$(mktemp -d)
log=$(mktemp)
trap 'rm -rf "$shadow" "$log"' EXIT
# A PATH of links to every program on today's PATH but the hidden ones.
IFS=: read -ra dirs <<< "$PATH"
for d in "${dirs[@]}"; do
  [ -d "$d" ] || continue
  for f in "$d"/*; do
    n=${f##*/}
    [[ " $hidden " == *" $n "* ]] && continue
    [ -x "$f" ] && [ ! -e "$shadow/$n" ] && ln -s "$f" "$shadow/$n"
  done
done
for n in $hidden; do
  if PATH=$shadow command -v "$n" >/dev/null; then
    echo "$n is still on the shadow PATH" >&2
    exit 1
  fi
done
echo "hidden: $hidden; no Vulkan driver; CI unset"
status=0
env -u CI PATH="$shadow" VK_ICD_FILENAMES=/nonexistent/icd.json VK_DRIVER_FILES=/nonexistent/icd.json \
  cargo test --release 2>&1 | tee "$log" || status=$?
if [ "$status" -ne 0 ]; then
  echo "the README's test command failed without the optional programs" >&2
  exit 1
fi
# Each missing component was said, not passed over in silence.
for why in "ffmpeg is not installed" "xvfb-run is not installed" "is not installed (apt-get install slurm-wlm munge)" \
  "there is no GPU adapter" "chromium is not installed"; do
  if ! grep -q "^skipped: .*$why" "$log"; then
    echo "no 'skipped:' line says: $why" >&2
    exit 1
  fi
done
echo "without the optional programs: $(grep -c '^skipped:' "$log") 'skipped:' lines, every test file passed"
