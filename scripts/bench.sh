#!/usr/bin/env bash
# Builds railwear in release once and runs every benchmark of railwear-bench, printing the
# markdown tables to stdout (progress goes to stderr). Benchmarks, not tests: nothing fails on a
# slow number. See docs/journal/benchmarks.md for the last recorded tables and their caveats.
#
# Usage: scripts/bench.sh [--quick] [--with-peers] [--json]
#   --quick       short windows (engine 1 s, launcher 1 s, memory 10 s, sweep 0.1 s, load 5 s
#                 with 2,000 rails) for a smoke run on a busy machine
#   --with-peers  also run MuJoCo/Drake via bench/peers/run_peers.sh (pip installs into a venv;
#                 Drake alone takes minutes)
#   --json        one JSON object per table instead of markdown
# Environment: CARGO_TARGET_DIR (default target), BENCH_BUDGET_S (wall budget per engine run,
# default 120).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
quick=0
peers=()
json=()
for a in "$@"; do
  case "$a" in
    --quick) quick=1 ;;
    --with-peers) peers=(--with-peers) ;;
    --json) json=(--json) ;;
    -h|--help) sed -n 2,13p "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option $a" >&2; exit 2 ;;
  esac
done
target="${CARGO_TARGET_DIR:-target}"
budget="${BENCH_BUDGET_S:-120}"
echo "bench.sh: cargo build --release (target dir $target) ..." >&2
cargo build --release --bins >&2
bench="$target/release/railwear-bench"
server="$target/release/railwear"

echo "# railwear benchmarks, $(date -u +%Y-%m-%dT%H:%M:%SZ), $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
echo
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg); $(uname -srm)"
echo
if [ "$quick" = 1 ]; then
  "$bench" "${json[@]}" engine --window 1 --sphere-duration 1 --budget "$budget"
  "$bench" "${json[@]}" peers --window 1 "${peers[@]}"
  "$bench" "${json[@]}" launcher --window 1 --mem-window 9
  "$bench" "${json[@]}" sweep --settle 0.1 --window 0.1
  "$bench" "${json[@]}" load --bin "$server" --rails 2000 --seconds 5
else
  "$bench" "${json[@]}" engine --budget "$budget"
  "$bench" "${json[@]}" peers "${peers[@]}"
  "$bench" "${json[@]}" launcher
  "$bench" "${json[@]}" sweep
  "$bench" "${json[@]}" load --bin "$server"
fi
