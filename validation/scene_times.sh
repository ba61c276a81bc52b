#!/usr/bin/env bash
# The user guide's table of the shipped scenes' times (GUIDE.md, Shipped
# scenes), measured:
#   validation/scene_times.sh [BINARY]
# runs each shipped config's command (render; compare for
# redshift_compare; animate for the animations) into a scratch folder,
# one after another, and prints for each `config: wall time (info's
# estimate)`. Run it on an otherwise idle machine; BINARY defaults to
# target/release/blackhole.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=validation/binary.sh
. validation/binary.sh "$@"
for cfg in configs/*.toml; do
  name=$(basename "$cfg" .toml)
  cmd=render
  [ "$name" = redshift_compare ] && cmd=compare
  grep -q '^\[animation\]' "$cfg" && cmd=animate
  args=(--set "image.png=$out/$name/$name.png")
  [ "$cmd" = animate ] && args+=(--set "animation.video=$out/$name.gif")
  # The animation's whole estimate where there is one, else the frame's.
  line=$("$bin" info "$cfg" 2>/dev/null | grep '^render time (estimate)' || true)
  estimate=$(echo "$line" | sed -n 's/.*animate: about \([0-9.]* [a-z]*\) for.*/\1/p')
  [ -n "$estimate" ] || estimate=$(echo "$line" | sed -n 's/^render time (estimate) *about \([0-9.]* [a-z]*\) .*/\1/p')
  t0=$(date +%s.%N)
  "$bin" "$cmd" -q "$cfg" "${args[@]}"
  t=$(echo "$(date +%s.%N) - $t0" | bc)
  printf '%s: %.1f s (%s)\n' "$name" "$t" "${estimate:-no estimate}"
done
