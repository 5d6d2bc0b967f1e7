#!/usr/bin/env bash
# Runs motiond with its commissioning UI on a fresh machine: builds the UI when frontend/dist is
# missing or older than its sources (npm ci + npm run build in frontend/), then builds and runs
# motiond (`cargo run --release`). Arguments go to motiond, e.g.
#     ./scripts/run.sh --db :memory: --cycle-us 500
set -euo pipefail
cd "$(dirname "$0")/.."

say() { echo "run.sh: $*" >&2; }

if ! command -v cargo >/dev/null 2>&1; then
    say "cargo not found; install the Rust toolchain (rustup) first"
    exit 1
fi
if ! command -v cc >/dev/null 2>&1; then
    # SQLite is compiled from source by libsqlite3-sys.
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        apt-get update -qq && apt-get install -y -qq gcc
    else
        say "no C compiler (cc) found; install one first: sudo apt-get install -y gcc"
        exit 1
    fi
fi

# The UI's build inputs newer than the last build (or no build at all).
ui_stale() {
    [ -f frontend/dist/index.html ] || return 0
    local newer
    newer=$(find frontend/src frontend/index.html frontend/package.json frontend/package-lock.json \
        frontend/vite.config.ts frontend/tsconfig.json -newer frontend/dist/index.html -print -quit \
        2>/dev/null || true)
    [ -n "$newer" ]
}

if [ ! -f frontend/package.json ]; then
    say "no frontend/ in this tree: starting motiond without the commissioning UI (the API, /docs and /metrics work; / says the UI is missing)"
elif ui_stale; then
    if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
        say "building the commissioning UI needs Node.js and npm, which are not installed."
        say "Install them (Debian/Ubuntu):  sudo apt-get install -y nodejs npm"
        say "then run ./scripts/run.sh again. (To start without the UI: cargo run --release)"
        exit 1
    fi
    # Vite 8 needs Node.js ^20.19 or >= 22.12.
    if ! node -e '
        const [a, b] = process.versions.node.split(".").map(Number);
        process.exit((a === 20 && b >= 19) || (a === 22 && b >= 12) || a >= 23 ? 0 : 1);'; then
        say "Node.js $(node --version) is too old to build the UI: it needs ^20.19 or >= 22.12."
        say "Install a newer nodejs package (e.g. from your distribution's backports) and run ./scripts/run.sh again."
        exit 1
    fi
    if [ -f frontend/dist/index.html ]; then
        say "frontend/ changed since the last build: rebuilding the commissioning UI"
    else
        say "building the commissioning UI (npm ci && npm run build in frontend/)"
    fi
    npm --prefix frontend ci --no-audit --no-fund
    npm --prefix frontend run build
fi

exec cargo run --release -- "$@"
