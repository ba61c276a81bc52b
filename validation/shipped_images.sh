#!/usr/bin/env bash
# The shipped images in img/ are the program's output for the shipped
# configs, byte for byte:
#   validation/shipped_images.sh [--write] [BINARY]
# renders every shipped config that takes under about 10 s at its own size
# (all but showcase.toml) into a scratch folder and compares each file it
# writes with the one in img/ (compare's summary, which holds wall times,
# excepted); --write copies them into img/ instead (showcase too). BINARY
# defaults to target/release/blackhole. Exit status 0 when all match.
set -euo pipefail
cd "$(dirname "$0")/.."
write=0
if [ "${1:-}" = --write ]; then write=1; shift; fi
# shellcheck source=validation/binary.sh
. validation/binary.sh "$@"

# config, command, then the files it writes into img/.
jobs=(
  "quick render quick.png"
  "side render side.png"
  "top render top.png"
  "seed render seed.png"
  "spectral_side render spectral_side.png spectral_side.exr"
  "planets render planets.png"
  "asteroids render asteroids.png"
  "stereo render stereo.png stereo_left.png stereo_right.png stereo_side_by_side.png stereo_anaglyph.png"
  "volumetric render volumetric.png"
  "thin_disk render thin_disk.png"
  "gold2020 render gold2020.png gold2020.exr gold2020.spectrum.csv"
  "sgra render sgra.png sgra.exr sgra.spectrum.csv"
  "m87 render m87.png m87.exr m87.spectrum.csv"
  "m87_torus render m87_torus.png m87_torus.exr m87_torus.spectrum.csv"
  "quasar render quasar.png quasar.spectrum.csv"
  "kerr_edge render kerr_edge.png"
  "kerr_thin render kerr_thin.png"
  "redshift_compare compare redshift_compare_shift_off.png redshift_compare_shift_off.exr redshift_compare_shift_on.png redshift_compare_shift_on.exr redshift_compare_side_by_side.png redshift_compare_delta_e.png"
  "orbit animate orbit.gif"
)
if [ $write -eq 1 ]; then
  jobs+=("showcase render showcase.png")
fi
bad=0
for job in "${jobs[@]}"; do
  read -r name cmd files <<<"$job"
  cfg=configs/$name.toml
  args=(--set "image.png=$out/$name.png")
  # The EXR follows image.png; the animation's frames and video too.
  [ "$cmd" = animate ] && args+=(--set "animation.video=$out/orbit.gif" --set "image.png=$out/orbit/orbit.png")
  t0=$(date +%s.%N)
  "$bin" "$cmd" -q "$cfg" "${args[@]}"
  t=$(echo "$(date +%s.%N) - $t0" | bc)
  for f in $files; do
    if [ $write -eq 1 ]; then
      cp "$out/$f" "img/$f"
    elif ! cmp -s "$out/$f" "img/$f"; then
      echo "img/$f differs from what $cmd $cfg writes now: regenerate with validation/shipped_images.sh --write" >&2
      bad=1
    fi
  done
  [ "$cmd" = compare ] && [ $write -eq 1 ] && cp "$out/redshift_compare_summary.txt" img/
  printf '%-18s %-8s %6.2f s  %s\n' "$name" "$cmd" "$t" "$files"
done
[ $bad -eq 0 ] && echo "shipped images: all match" || exit 1
