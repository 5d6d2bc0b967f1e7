#!/usr/bin/env bash
# Runs every test of motiond on a fresh machine: Rust unit, scenario, property and
# integration tests (the integration tests start the real motiond binary on free ports with
# temporary databases), the UI's logic and browser tests, the generated clients and
# schemathesis. Builds and installs whatever it needs first (Debian packages through apt-get,
# as root or with sudo; otherwise it stops and prints the command to run).
#
# A test that cannot run here (no network namespace, no mount namespace, …) fails when CI is
# set (CI=true) and is listed as SKIPPED in the summary at the end otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

say() { echo "test-all: $*" >&2; }
started=$(date +%s)
declare -a phases=()
phase_start=$started
phase() {
    local now
    now=$(date +%s)
    phases+=("$1: $((now - phase_start)) s")
    phase_start=$now
}

# Debian packages: as root directly, else through sudo, else say exactly what to run.
apt_install() {
    if [ "$(id -u)" = 0 ]; then
        apt-get update -qq && apt-get install -y -qq "$@"
    elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        sudo apt-get update -qq && sudo apt-get install -y -qq "$@"
    else
        say "missing Debian packages; install them first:  sudo apt-get install -y $*"
        exit 1
    fi
}

if ! command -v cargo >/dev/null 2>&1; then
    say "cargo not found; install the Rust toolchain (rustup) first"
    exit 1
fi
# SQLite is compiled from source by libsqlite3-sys; the namespace tests use ip and unshare.
command -v cc >/dev/null 2>&1 || apt_install gcc
command -v ip >/dev/null 2>&1 || apt_install iproute2
command -v unshare >/dev/null 2>&1 || apt_install util-linux

# Tests that could not run write a line each here (tests/common, backend/ethercat/tests).
export MOTIOND_SKIPPED_LOG=$root/target/skipped-tests.txt
mkdir -p "$root/target"
rm -f "$MOTIOND_SKIPPED_LOG"

cargo test --workspace --all-targets 2>&1
phase "Rust tests"
# The binary the browser tests, the generated clients and schemathesis start: the one this
# build made for the integration tests. A `cargo build -p motiond` after it would build the
# server again (2 min: without the dev-dependencies the dependencies' features differ).
# Cargo's own answer: CARGO_TARGET_DIR, a target-dir in its config, or target/.
target_dir=$(cargo metadata --no-deps --format-version 1 |
    python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
export MOTIOND_BIN=$target_dir/debug/motiond
if [ ! -x "$MOTIOND_BIN" ]; then
    say "the test build left no motiond binary at $MOTIOND_BIN"
    exit 1
fi

# Who may depend on whom (docs/ARCHITECTURE.md): no import cycle, no upward import.
python3 scripts/check-layers.py
# Clippy (the workspace's [workspace.lints]): every warning is an error here.
cargo clippy --version >/dev/null 2>&1 || rustup component add clippy
cargo clippy --workspace --all-targets -- -D warnings 2>&1
phase "layers and clippy"

# --- Frontend (frontend/, tests/e2e/) ------------------------------------------------------
# The UI's API types must match openapi/openapi.json, the UI must build, its logic tests
# (Vitest) must pass, and the browser tests drive the real motiond binary with headless
# Debian Chromium (playwright-core; never a downloaded browser).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    apt_install nodejs npm
fi
# Vite 8 needs Node.js ^20.19 or >= 22.12.
if ! node -e '
    const [a, b] = process.versions.node.split(".").map(Number);
    process.exit((a === 20 && b >= 19) || (a === 22 && b >= 12) || a >= 23 ? 0 : 1);'; then
    say "Node.js $(node --version) is too old for the UI's build and tests: it needs ^20.19 or >= 22.12"
    exit 1
fi
command -v chromium >/dev/null 2>&1 || apt_install chromium
(cd frontend && npm ci --no-audit --no-fund && npm run check:api && npm run build && NO_COLOR=1 npm test)
phase "UI build and Vitest"
# The browser tests start $MOTIOND_BIN.
(cd tests/e2e && npm ci --no-audit --no-fund && npm test)
phase "Chromium e2e"

# --- Client generation (tests/client/) -----------------------------------------------------
# openapi-python-client and openapi-typescript (pinned) generate clients from
# openapi/openapi.json: no warning, no operation missing. Then an MES script drives the real
# motiond ($MOTIOND_BIN) through the generated Python client.
if ! command -v python3 >/dev/null 2>&1; then
    apt_install python3 python3-venv
fi
./tests/client/check.sh
phase "generated clients"

# --- Schemathesis (scripts/schemathesis.sh, tests/schemathesis/) ---------------------------
# The real binary ($MOTIOND_BIN) against its own OpenAPI document, every
# check, a fixed number of test cases per operation and phase, fixed seed: with an admin token
# (≥ 10 000 requests), and without credentials while authentication is on (every operation but
# login, logout and the session query must be 401; a handful of variants each).
# Both runs at once, each with its own motiond and reports (one Python process each: the two
# cores are used without schemathesis's workers); the virtualenv first, which they share.
ST_SETUP_ONLY=1 ./scripts/schemathesis.sh
none_log=$target_dir/schemathesis-none.log
# In a process group of its own, which test-all stops whenever it ends (the admin run failed,
# an interrupt): its timeout, schemathesis and motiond with it.
setsid env ST_AUTH=none ST_REPORT_DIR="$target_dir/schemathesis-none" \
    ./scripts/schemathesis.sh >"$none_log" 2>&1 &
none_pid=$!
trap 'kill -TERM -- "-$none_pid" 2>/dev/null || kill -TERM "$none_pid" 2>/dev/null || true' EXIT
admin_rc=0
ST_AUTH=admin ST_REPORT_DIR="$target_dir/schemathesis" ./scripts/schemathesis.sh || admin_rc=$?
none_rc=0
wait "$none_pid" || none_rc=$?
trap - EXIT
echo "test-all: schemathesis without credentials (run beside the admin run):"
cat "$none_log"
phase "schemathesis (admin, and without credentials at the same time)"
if [ "$admin_rc" != 0 ] || [ "$none_rc" != 0 ]; then
    say "schemathesis failed (admin: exit $admin_rc; without credentials: exit $none_rc)"
    exit 1
fi

echo
echo "test-all: summary ($(( $(date +%s) - started )) s in all)"
for p in "${phases[@]}"; do echo "  $p"; done
if [ -s "$MOTIOND_SKIPPED_LOG" ]; then
    echo "test-all: SKIPPED (could not run on this machine; under CI=true they fail instead):"
    sed 's/^/  SKIPPED /' "$MOTIOND_SKIPPED_LOG"
fi
