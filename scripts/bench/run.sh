#!/usr/bin/env bash
# Service benchmarks (see docs/benchmarks.md, "## Service"). Needs root for SCHED_FIFO and for
# installing cyclictest (Debian rt-tests). Usage: scripts/bench/run.sh [--quick]
set -euo pipefail
cd "$(dirname "$0")/../.."
target=${CARGO_TARGET_DIR:-target}
cargo build --release --bin motiond --example bench
if ! command -v cyclictest >/dev/null 2>&1; then
    apt-get update -qq && apt-get install -y -qq rt-tests
fi
python3 scripts/bench/service.py "$target/release/motiond" "$target/release/examples/bench" "$target/bench-service" "$@"
echo "results: $target/bench-service/results.json"
