# Sourced by the measuring scripts beside it, from the repository's root:
# `bin` is the binary they run (their first argument, else
# target/release/blackhole), `out` a scratch folder removed on exit.
bin=$(realpath "${1:-target/release/blackhole}")
[ -x "$bin" ] || { echo "no binary $bin: cargo build --release first" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
