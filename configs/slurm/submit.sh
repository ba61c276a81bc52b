#!/bin/bash
# Submits a render as a Slurm job array and the step that depends on it:
#   configs/slurm/submit.sh tiles  N CONFIG [--set KEY=VALUE]...   # N tiles, then merge
#   configs/slurm/submit.sh frames N CONFIG [--set KEY=VALUE]...   # N runs of frames, then the video
#   configs/slurm/submit.sh library LIBRARY CONFIG [--set KEY=VALUE]...   # a GRMHD image library, then its summary
# Prints the two job ids ("ARRAY FOLLOW-UP"). A failed task runs again
# alone with the same N: sbatch --array=I configs/slurm/tiles.sbatch N CONFIG ...
# (then merge.sbatch), or frames.sbatch likewise (then video.sbatch). Job logs go to $BLACKHOLE_LOGS
# (default ./slurm-logs). $BLACKHOLE names the binary (default: blackhole
# on the PATH, made absolute here so that jobs find it); other sbatch
# options come from Slurm's own SBATCH_* variables (SBATCH_PARTITION...).
set -euo pipefail
usage="usage: $0 tiles|frames N CONFIG [--set KEY=VALUE]...  or  $0 library LIBRARY CONFIG [--set KEY=VALUE]..."
[ $# -ge 3 ] || { echo "$usage" >&2; exit 2; }
kind=$1 n=$2
shift 2
case $kind in
  tiles) array=tiles.sbatch after=merge.sbatch ;;
  frames) array=frames.sbatch after=video.sbatch ;;
  library)
    # n is the library file; its images are snapshots x inclinations x R-highs.
    lib=$n
    [ -r "$lib" ] || { echo "library: cannot read $lib" >&2; exit 2; }
    count() { sed -n "s/^[[:space:]]*$1[[:space:]]*=[[:space:]]*\([^#]*\).*/\1/p" "$lib" | tail -n 1 | wc -w; }
    n=$(($(count dumps) * $(count inclinations) * $(count r_high)))
    ;;
  *) echo "$usage" >&2; exit 2 ;;
esac
case $n in
  '' | *[!0-9]* | 0) echo "N must be a whole number of tasks, at least 1 (got '$n')" >&2; exit 2 ;;
esac
here=$(cd "$(dirname "$0")" && pwd)
bin=${BLACKHOLE:-blackhole}
if [[ $bin == */* ]]; then
  [ -x "$bin" ] || { echo "BLACKHOLE=$bin: no such program (build it: cargo build --release)" >&2; exit 1; }
  bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
else
  found=$(command -v "$bin") || { echo "no $bin on the PATH: set BLACKHOLE to the binary" >&2; exit 1; }
  bin=$found
fi
export BLACKHOLE=$bin
logs=${BLACKHOLE_LOGS:-slurm-logs}
mkdir -p "$logs"
if [ "$kind" = library ]; then
  first=$(sbatch --parsable --array="0-$((n - 1))" --output="$logs/%x-%A_%a.out" \
    "$here/library.sbatch" "$lib" "$@")
  first=${first%%;*}
  second=$(sbatch --parsable --dependency="afterok:$first" --kill-on-invalid-dep=yes \
    --output="$logs/%x-%j.out" "$here/library.sbatch" --summary "$lib")
  echo "$first ${second%%;*}"
  exit 0
fi
first=$(sbatch --parsable --array="0-$((n - 1))" --output="$logs/%x-%A_%a.out" \
  "$here/$array" "$n" "$@")
first=${first%%;*}
second=$(sbatch --parsable --dependency="afterok:$first" --kill-on-invalid-dep=yes \
  --output="$logs/%x-%j.out" "$here/$after" "$@")
echo "$first ${second%%;*}"
