#!/usr/bin/env bash
# Generates clients from openapi/openapi.json with pinned generators and fails on any warning or
# dropped operation, then runs the MES script (mes_example.py) through the generated Python
# client against the real motiond. Needs python3 (≥ 3.10, with venv), frontend/node_modules
# (npm ci) and motiond ($MOTIOND_BIN, else target/debug/motiond: cargo build -p motiond).
# Installs the Python side into target/client-venv (from tests/client/requirements.txt, again
# when that file changes).
set -euo pipefail
cd "$(dirname "$0")/../.."

venv=target/client-venv
if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
    apt-get update -qq && apt-get install -y -qq python3-venv
fi
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if ! cmp -s tests/client/requirements.txt "$venv/requirements.installed"; then
    "$venv/bin/pip" install --quiet --disable-pip-version-check -r tests/client/requirements.txt
    cp tests/client/requirements.txt "$venv/requirements.installed"
fi
exec "$venv/bin/python" tests/client/check.py
