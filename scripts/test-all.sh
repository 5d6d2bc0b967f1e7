#!/usr/bin/env bash
# Runs every test of motiond on a fresh machine: Rust unit, scenario, property and
# integration tests (the integration tests start the real motiond binary on free ports with
# temporary databases). Builds whatever it needs first.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null 2>&1; then
    echo "test-all: cargo not found; install the Rust toolchain (rustup) first" >&2
    exit 1
fi
if ! command -v cc >/dev/null 2>&1; then
    # SQLite is compiled from source by libsqlite3-sys.
    apt-get update -qq && apt-get install -y -qq gcc
fi

cargo test --workspace --all-targets 2>&1
