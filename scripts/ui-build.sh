#!/usr/bin/env bash
# Builds the commissioning UI into frontend/dist (the files motiond serves at /).
# Installs the npm dependencies first when they are missing or older than the lock file.
set -euo pipefail
cd "$(dirname "$0")/../frontend"

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    echo "ui-build: node and npm not found; install Node.js 20.19 or newer" >&2
    exit 1
fi
if ! node -e 'const [a,b]=process.versions.node.split(".").map(Number); process.exit(a>20||(a===20&&b>=19)?0:1)'; then
    echo "ui-build: Node.js $(node --version) is too old; Vite needs 20.19 or newer" >&2
    exit 1
fi
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
    npm ci --no-audit --no-fund
fi
npm run build
