#!/usr/bin/env bash
# Gold et al. 2020's five analytic tests at their set-up, as the binary
# renders them today: the tables of REFERENCE.md section 19 and of
# PERFORMANCE.md's radiative transfer section come from this script.
#   validation/transfer_table.sh [BINARY]
# BINARY defaults to target/release/blackhole. It prints two Markdown
# tables: the fluxes (ours in closed form, the default, and integrated at
# 128 x 128 one ray a pixel as ipole takes them; at 256 x 256; the camera
# at 1e4 and 1e5 M with the same 30 M field) beside the published values
# and ipole's, and the wall and CPU seconds of the two 128 x 128 renders.
# validation/tests/transfer.rs checks REFERENCE.md's closed-form column
# against the binary: rerun this script when the fluxes move.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=validation/binary.sh
. validation/binary.sh "$@"

# The published values (Gold et al. 2020, table 1) and ipole's unpolarised
# totals at this set-up (commit cbbc370, make MODEL=analytic, ipole -par
# tests/analytic/analytic.par --model=N; measured 2026-12-04).
published=(1.6465 1.4360 0.4418 0.2710 0.0255)
ipole=(1.65763 1.45007 0.448791 0.274148 0.0259092)
# G M / c^2 of the set-up's hole (m): 4.063e6 solar masses.
m_metres=5.999439e9

# render N PIXELS CAMERA_M [extra --set ...]: the total flux (Jy, from the
# spectrum file) and "wall cpu" seconds.
render() {
  local n=$1 px=$2 cam=$3
  shift 3
  local spin=0.9
  [ "$n" = 2 ] && spin=0
  local pos fov
  pos=$(awk -v r="$cam" -v m="$m_metres" 'BEGIN { pi = atan2(0, -1);
    printf "[%.9e, 0.0, %.9e]", r * m * sin(pi / 3), r * m * cos(pi / 3) }')
  fov=$(awk -v r="$cam" 'BEGIN { printf "%.9f", 30 / r * 180 / atan2(0, -1) }')
  [ "$cam" = 1000 ] && pos="" && fov=""
  local args=(--set "medium.test=$n" --set "black_hole.spin=$spin"
    --set "image.width=$px" --set "image.height=$px" --set image.samples=1
    --set "image.png=$out/g.png")
  [ -n "$pos" ] && args+=(--set "camera.position=$pos" --set "camera.fov=$fov")
  local t
  t=$( { TIMEFORMAT='%R %U %S'; time "$bin" render -q configs/gold2020.toml "${args[@]}" "$@" >/dev/null; } 2>&1 )
  local flux
  flux=$(sed -n 2p "$out/g.spectrum.csv" | cut -d, -f2)
  echo "$flux $(echo "$t" | awk '{ printf "%.2f %.2f", $1, $2 + $3 }')"
}

rows=()
times=()
for n in 1 2 3 4 5; do
  read -r closed cw cc <<<"$(render "$n" 128 1000)"
  read -r integrated iw ic <<<"$(render "$n" 128 1000 --set physics.closed_form=false)"
  read -r fine _ _ <<<"$(render "$n" 256 1000)"
  read -r far4 _ _ <<<"$(render "$n" 128 1e4)"
  read -r far5 _ _ <<<"$(render "$n" 128 1e5)"
  p=${published[$((n - 1))]}
  i=${ipole[$((n - 1))]}
  rows+=("$(awk -v n="$n" -v p="$p" -v c="$closed" -v g="$integrated" -v f="$fine" \
    -v a="$far4" -v b="$far5" -v i="$i" 'function pc(x, y) { return sprintf("%+.2f%%", 100 * (x / y - 1)) }
    BEGIN { printf "| %d | %s | %#.6g (%s) | %#.6g (%+.1e) | %#.6g (%+.1e) | %+.2f%% | %+.2f%% | %s (%s) |",
      n, p, c, pc(c, p), g, g / c - 1, f, f / c - 1, 100 * (a / c - 1), 100 * (b / c - 1), i, pc(i, p) }')")
  times+=("| $n | $cw / $cc | $iw / $ic |")
done

echo "| test | published (Jy) | ours, closed form (Jy) | integrated | 256 x 256 | camera at 1e4 M | at 1e5 M | ipole (Jy) |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "| test | closed form: wall / CPU (s) | integrated: wall / CPU (s) |"
echo "|---|---|---|"
printf '%s\n' "${times[@]}"
