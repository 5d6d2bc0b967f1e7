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

# --- Frontend (frontend/, tests/e2e/) ------------------------------------------------------
# The UI's API types must match openapi/openapi.json, the UI must build, its logic tests
# (Vitest) must pass, and the browser tests drive the real motiond binary with headless
# Debian Chromium (playwright-core; never a downloaded browser).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "test-all: node/npm not found; install Node.js 20.19 or newer" >&2
    exit 1
fi
command -v chromium >/dev/null 2>&1 || (apt-get update && apt-get install -y chromium)
(cd frontend && npm ci --no-audit --no-fund && npm run check:api && npm run build && NO_COLOR=1 npm test)
# The browser tests start target/debug/motiond (the workspace target/, whatever the caller's CARGO_TARGET_DIR).
env -u CARGO_TARGET_DIR cargo build -p motiond 2>&1
(cd tests/e2e && npm ci --no-audit --no-fund && env -u CARGO_TARGET_DIR npm test)

# --- Client generation (tests/client/) -----------------------------------------------------
# openapi-python-client and openapi-typescript (pinned) generate clients from
# openapi/openapi.json: no warning, no operation missing. Then an MES script drives the real
# motiond (target/debug/motiond, built above) through the generated Python client.
if ! command -v python3 >/dev/null 2>&1; then
    echo "test-all: python3 not found; install Python 3.10 or newer" >&2
    exit 1
fi
./tests/client/check.sh

# --- Schemathesis (scripts/schemathesis.sh, tests/schemathesis/) ---------------------------
# The real binary (target/debug/motiond, built above) against its own OpenAPI document, every
# check, ≥ 10 000 requests each, fixed seed: with an admin token, and without credentials while
# authentication is on (every operation but login, logout and the session query must be 401).
ST_AUTH=admin ./scripts/schemathesis.sh
ST_AUTH=none ./scripts/schemathesis.sh
