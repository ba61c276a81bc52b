#!/bin/sh
# Builds the web viewer's static site (default: `site` in cargo's target
# folder, $CARGO_TARGET_DIR where set, else target/; or the folder given):
# the crate compiled to wasm32 with wgpu's WebGPU backend, its JavaScript
# glue made by wasm-bindgen (the version in Cargo.lock), the page, the
# shipped scenes and their assets, the disk's at web resolution
# (regenerated from the same fixed seeds by `blackhole assets`). Serve it
# with `blackhole serve`.
#
# Needs: rustup target add wasm32-unknown-unknown
#        cargo install wasm-bindgen-cli --version <Cargo.lock's wasm-bindgen>
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
# Cargo's target folder as cargo itself resolves it (CARGO_TARGET_DIR
# relative to the current folder, or a config's build.target-dir), taken
# before leaving the current folder; the folder given too.
target=$(cargo metadata --format-version 1 --no-deps --manifest-path "$root/Cargo.toml" |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
[ -n "$target" ] || { echo "src/web/build.sh: cargo metadata names no target folder" >&2; exit 1; }
out=${1:-$target/site}
case $out in /*) ;; *) out=$PWD/$out ;; esac
cd "$root"
export CARGO_TARGET_DIR="$target"

# What each long step is doing, and how long it took.
start=$(date +%s)
step() {
    now=$(date +%s)
    [ -z "${step_at:-}" ] || echo "    ($((now - step_at)) s)"
    step_at=$now
    echo "src/web/build.sh: $*"
}

want=$(sed -n '/^name = "wasm-bindgen"$/{n;s/^version = "\(.*\)"$/\1/p;q}' Cargo.lock)
have=$(wasm-bindgen --version 2>/dev/null | sed 's/^wasm-bindgen //;s/ .*//') || have=
if [ "$have" != "$want" ]; then
    echo "src/web/build.sh: needs wasm-bindgen $want (Cargo.lock's), found '${have:-none}':" >&2
    echo "  cargo install wasm-bindgen-cli --version $want" >&2
    exit 1
fi
if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
    echo "src/web/build.sh: needs the wasm32 target: rustup target add wasm32-unknown-unknown" >&2
    exit 1
fi

# The page's module (profile `web`: optimised for size, linked whole) and
# the native command that makes the assets. Cargo's own lines show the
# crates compiled; the link-time optimisation at the end is silent.
step "compiling the page's module for wasm32 (profile web, link-time optimised: minutes, see the guide)"
cargo rustc --lib --crate-type cdylib --target wasm32-unknown-unknown --profile web
step "compiling the native blackhole for the assets (release)"
cargo build --release --bin blackhole

tmp="$out.part"
rm -rf "$tmp"
mkdir -p "$tmp/configs" "$tmp/spectral_assets"
step "making the JavaScript glue (wasm-bindgen)"
wasm-bindgen --target web --no-typescript --out-dir "$tmp/pkg" \
    "$target/wasm32-unknown-unknown/web/blackhole.wasm"
cp src/web/index.html "$tmp/"
cp configs/*.toml "$tmp/configs/"
# The disk's assets at web resolution, from the same seeds: the texture
# 512 texels (1024 on the desktop), the spectral set 256 (512). The sky
# stays at the desktop's 4096: at 2048 its stars show as blocks at a 40
# degree field. The star catalogue and the meshes as shipped.
step "the disk's assets at web resolution (blackhole assets)"
for only in "disk --disk-size 512" "spectral --spectral-size 256"; do
    # shellcheck disable=SC2086
    "$target/release/blackhole" assets --out "$tmp/spectral_assets" --only $only \
        >"$tmp/assets.log" 2>&1 || { cat "$tmp/assets.log" >&2; exit 1; }
done
rm "$tmp/assets.log"
cp -r spectral_assets/sky.png spectral_assets/stars spectral_assets/meshes "$tmp/spectral_assets/"

# The scene list: each shipped scene with the first line of its comment.
{
    printf '{"default": "quick", "scenes": ['
    sep=
    for f in configs/*.toml; do
        name=$(basename "$f" .toml)
        about=$(sed -n '1s/^# *//p' "$f" | sed 's/\\/\\\\/g; s/"/\\"/g')
        printf '%s\n  {"name": "%s", "about": "%s"}' "$sep" "$name" "$about"
        sep=,
    done
    printf '\n]}\n'
} > "$tmp/scenes.json"

step "copying the scenes and assets; gzipped copies of the module"
# Gzipped copies of the largest files, which `blackhole serve` sends to
# browsers that take gzip (static hosts compress by themselves).
gzip -9k "$tmp/pkg/blackhole_bg.wasm" "$tmp/pkg/blackhole.js"

rm -rf "$out"
mv "$tmp" "$out"
wasm="$out/pkg/blackhole_bg.wasm"
step "done in $(($(date +%s) - start)) s"
echo "built the site in $out: wasm $(wc -c < "$wasm") bytes, $(wc -c < "$wasm.gz") gzipped"
