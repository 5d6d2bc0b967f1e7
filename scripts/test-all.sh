#!/usr/bin/env bash
# Runs every test of motiond on a fresh machine: Rust unit, scenario, property and
# integration tests (the integration tests start the real motiond binary).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --all-targets 2>&1
