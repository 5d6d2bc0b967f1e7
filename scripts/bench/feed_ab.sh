#!/usr/bin/env bash
# The websocket feed's CPU, two (or more) motiond binaries alternately in one run
# (docs/benchmarks.md, "Websocket feed: shared topic text"): each run starts one binary with 64
# moving axes, connects CLIENTS websocket clients subscribed to every axis at 50 Hz
# (target/release/examples/bench ws), and reads motiond's task-clock with `perf stat` over 8 s
# after 6 s of warm-up, and what the load generator received; then again over 8 s once the
# clients are gone (the same moving axes): the difference is what serving the clients costs
# (the feed, the sends, and on loopback the clients' receive path inside `sendto`). Task-clock is
# what the process used on all its threads; it reads lower than feed.py's CPU, whose window
# includes connecting.
# Usage: scripts/bench/feed_ab.sh ROUNDS CLIENTS MOTIOND_A MOTIOND_B [...]
set -euo pipefail
rounds=$1; clients=$2; shift 2
bench=${BENCH:-target/release/examples/bench}
command -v perf >/dev/null || { echo "needs perf (Debian: linux-perf)" >&2; exit 1; }
# The machine-speed reference (the planner's sample, ns) with the figures, so that they can be
# set against another machine's.
echo "reference: $("$bench" reference)"
out=$(mktemp -d)
motiond=
# perf's figures without a locale's digit grouping; no motiond left running on a failure.
export LC_ALL=C
trap '[ -n "$motiond" ] && kill "$motiond" 2>/dev/null; rm -rf "$out"' EXIT
port=18190
for _ in $(seq "$rounds"); do
    for bin in "$@"; do
        port=$((port + 1))
        "$bin" --db :memory: --listen "127.0.0.1:$port" --max-connections 4000 >/dev/null 2>&1 &
        motiond=$!
        for _ in $(seq 100); do curl -sf "127.0.0.1:$port/api/v1/axes" >/dev/null && break; sleep 0.1; done
        axes=$(python3 - "$port" <<'PY'
import json, sys, urllib.request
port = sys.argv[1]
def post(path, body):
    r = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=json.dumps(body).encode(),
                               method="POST", headers={"content-type": "application/json"})
    with urllib.request.urlopen(r) as f:
        assert f.status in (201, 202), (path, f.status)
cfg = {"unit": "mm", "dynamics": {"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0,
                                   "jerk": 25000.0, "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0}}
axes = ["x", "y", "spindle"]
while len(axes) < 64:
    axes.append(f"a{len(axes)}")
    post("/api/v1/axes", dict(cfg, name=axes[-1]))
for a in axes:
    post(f"/api/v1/axes/{a}/power?wait=true", {})
    post(f"/api/v1/axes/{a}/move-velocity", {"velocity": 360.0 if a == "spindle" else 8.0})
print(" ".join(axes))
PY
)
        # shellcheck disable=SC2086
        "$bench" ws "127.0.0.1:$port" "$clients" 50 18 $axes >"$out/load.json" 2>&1 &
        load=$!
        sleep 6
        ms=$(perf stat -e task-clock -p "$motiond" -- sleep 8 2>&1 | awk '/task-clock/ {print $1}')
        wait "$load"
        # What was delivered over the whole 18 s (a build that delivers less must not look cheaper).
        delivered=$(python3 -c 'import json,sys; r=json.loads(open(sys.argv[1]).read().strip().splitlines()[-1]); print(r["updates_per_s"], "of", r["clients"]*len(sys.argv[2:])*50)' "$out/load.json" $axes)
        # The same machine with no client (the cycle thread with 64 moving axes, the runtime
        # idle): what is left of the figure above when it is taken away is what serving the
        # clients costs.
        base=$(perf stat -e task-clock -p "$motiond" -- sleep 8 2>&1 | awk '/task-clock/ {print $1}')
        serving=$(awk -v a="$ms" -v b="$base" 'BEGIN { printf "%.0f", a - b }')
        echo "$bin task_clock_ms_per_8s=$ms without_clients=$base serving=$serving updates_per_s=$delivered"
        kill "$motiond"; wait "$motiond" 2>/dev/null || true
        motiond=
    done
done
