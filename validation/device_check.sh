#!/usr/bin/env bash
# The checks to run once where a real GPU is at hand (about 10 minutes on a
# 16-core host): the release build, the GPU tests, and the GPU benchmarks,
# with the adapter's name, each figure in the device's own time
# (timestamps) beside the wall time:
#   1. gpu_wall_* / gpu_time_*: 1080p and 4K frames, RGB and spectral, the
#      trace alone, the viewer's frame (trace + display, nothing read
#      back) and its half-size preview;
#   2. frame_1080p in one process after the CPU's frames (the long process)
#      and alone (a fresh one), each GPU frame's wall time, GPU time and
#      page faults printed, to tell a slower frame's device share from its
#      host share.
# Results go to $OUT (default target/device): logs, and criterion's
# estimates.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-target/device}
mkdir -p "$out"
export BLACKHOLE_BENCH_SECONDS=${BLACKHOLE_BENCH_SECONDS:-3}
if command -v nvidia-smi >/dev/null; then
  nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,power.draw \
    --format=csv >"$out/adapter.txt" 2>&1 || true
fi
nproc >>"$out/adapter.txt"

echo "== build"
cargo build --release --all-targets 2>&1 | tail -2

echo "== GPU tests"
CI=true cargo test --release --test gpu --test kerr 2>&1 | tee "$out/gpu_tests.log" |
  grep -E "test result|FAILED|panicked" || true

echo "== point stars' images against the exact lens (the 1% aim on hardware f32)"
CI=true cargo test --release --test footprint gpu_point_star -- --nocapture 2>&1 |
  tee "$out/star_images.log" | grep -E "^GPU:|worst|test result|FAILED" || true

echo "== frames that stay on the GPU"
cargo bench --bench render -- "gpu_" 2>&1 | tee "$out/frames.log" |
  grep -E "^GPU:|time:|skipped|^gpu_" || true

echo "== the 1080p frame after the CPU's frames, in one process"
cargo bench --bench render -- "frame_1080p" 2>&1 | tee "$out/long.log" |
  grep -E "time:|wall|^frame_1080p" || true

echo "== the same frame alone"
cargo bench --bench render -- "frame_1080p/side_rgb_gpu$" 2>&1 | tee "$out/fresh.log" |
  grep -E "time:|wall|^frame_1080p" || true

cp -r target/criterion "$out/criterion" 2>/dev/null || true
echo "device checks done: $out"
