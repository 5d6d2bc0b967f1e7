#!/usr/bin/env bash
# Schemathesis (pinned in tests/schemathesis/requirements.txt) against the real motiond binary:
# starts `motiond serve --listen 127.0.0.1:0 --db :memory:` (demo axes x, y, spindle), lays a
# little test data beside them (an axis and cam tables for the path parameters to find), loads
# the schema from the running server (/openapi.json) and runs every phase (examples, coverage,
# fuzzing, stateful) with every check (`-c all`: server errors, status codes, content types,
# response headers and bodies against the document, negative data rejected, positive data
# accepted, undeclared methods, …), with a fixed seed, then prints how many requests it made.
# The run is bounded by count (test cases per operation and phase), not by time: a slower
# machine takes longer for the same requests and still passes. A safety timeout only catches a
# hang (a run that stops making progress). Exits non-zero on any failure, when the safety
# timeout strikes, or when it made fewer requests than it should. Needs python3 (≥ 3.10, with venv) and a built motiond; never
# builds anything. Extra arguments go to `st run`, e.g.
#     scripts/schemathesis.sh -H 'Authorization: Bearer …'
#     ST_MIN_REQUESTS=0 scripts/schemathesis.sh --include-path-regex '^/api/v1/cam-tables'
# Environment (defaults in brackets):
#     ST_AUTH          how motiond and schemathesis authenticate [off]:
#                      off    no user exists, authentication is off (motiond's default on
#                             loopback): every request is served without credentials, so the
#                             `ignored_auth` check (which expects 401 without them) does not apply
#                      admin  an admin user exists; schemathesis sends an admin API token
#                      none   an admin user exists; schemathesis sends no credentials: every
#                             operation but login, logout and the session query must be a 401
#     MOTIOND_BIN      the binary [target/debug/motiond]; a relative path is taken from the
#                      caller's working directory
#     ST_MAX_EXAMPLES  test cases per operation and phase (`--max-examples`) [admin and off:
#                      150; none: 5 — without credentials every operation answers 401 whatever
#                      the body, so a handful of variants per operation tells all there is]
#     ST_SEED          the seed (`--seed`) [20261125]
#     ST_WORKERS       concurrent workers [1] (more trip a CPython 3.11 `ast` race in hypothesis)
#     ST_SAFETY_S      safety timeout in seconds, only against a hang; never the measure of
#                      a slow machine [3600]
#     ST_MIN_REQUESTS  fail when fewer requests were made (0: no minimum) [admin and off:
#                      10000; none: 500]
#     ST_REPORT_DIR    where the NDJSON event log and the JUnit report go [target/schemathesis]
#     ST_SETUP_ONLY    1: make the virtualenv, then stop (no server, no run) [0]
set -euo pipefail
caller_dir=$(pwd)
cd "$(dirname "$0")/.."
root=$(pwd)

say() { echo "schemathesis.sh: $*" >&2; }

bin=${MOTIOND_BIN:-$root/target/debug/motiond}
case $bin in /*) ;; *) bin=$caller_dir/$bin ;; esac
if [ ! -x "$bin" ]; then
    say "no motiond binary at $bin (build it with 'cargo build -p motiond' or set MOTIOND_BIN)"
    exit 1
fi
seed=${ST_SEED:-20261125}
workers=${ST_WORKERS:-1}
safety=${ST_SAFETY_S:-3600}
auth=${ST_AUTH:-off}
case $auth in off|admin|none) ;; *) say "ST_AUTH must be off, admin or none"; exit 1 ;; esac
if [ "$auth" = none ]; then
    max_examples=${ST_MAX_EXAMPLES:-5}
    min_requests=${ST_MIN_REQUESTS:-500}
else
    max_examples=${ST_MAX_EXAMPLES:-150}
    min_requests=${ST_MIN_REQUESTS:-10000}
fi
report_dir=${ST_REPORT_DIR:-$root/target/schemathesis}
case $report_dir in /*) ;; *) report_dir=$caller_dir/$report_dir ;; esac

# --- The virtualenv (again when requirements.txt changes) ----------------------------------
venv=tests/schemathesis/.venv
if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
    apt-get update -qq && apt-get install -y -qq python3-venv
fi
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if ! cmp -s tests/schemathesis/requirements.txt "$venv/requirements.installed"; then
    "$venv/bin/pip" install --quiet --disable-pip-version-check -r tests/schemathesis/requirements.txt
    cp tests/schemathesis/requirements.txt "$venv/requirements.installed"
fi
if [ "${ST_SETUP_ONLY:-0}" = 1 ]; then
    exit 0 # the virtualenv only (before runs that share it start at once)
fi

# --- The server ----------------------------------------------------------------------------
work=$(mktemp -d)
server_pid=
cleanup() {
    if [ -n "$server_pid" ] && kill -0 "$server_pid" 2>/dev/null; then
        kill "$server_pid" 2>/dev/null || true
        for _ in $(seq 50); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$server_pid" 2>/dev/null || true
    fi
    rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

if [ "$auth" = off ]; then
    "$bin" serve --listen 127.0.0.1:0 --db :memory: >"$work/server.log" 2>&1 &
else
    MOTIOND_ADMIN_USER=st-admin MOTIOND_ADMIN_PASSWORD=st-admin-password \
        "$bin" serve --listen 127.0.0.1:0 --db :memory: >"$work/server.log" 2>&1 &
fi
server_pid=$!
addr=
for _ in $(seq 300); do
    addr=$(sed -n 's#.*listening on http://\([^ ]*\).*#\1#p' "$work/server.log" | head -n 1)
    [ -n "$addr" ] && break
    if ! kill -0 "$server_pid" 2>/dev/null; then
        say "motiond exited before listening:"; cat "$work/server.log" >&2; exit 1
    fi
    sleep 0.1
done
if [ -z "$addr" ]; then
    say "motiond did not say where it listens within 30 s:"; cat "$work/server.log" >&2; exit 1
fi
base=http://$addr
say "motiond $("$bin" --version 2>/dev/null | awk '{print $NF}') ($bin) at $base"

# --- Test data -----------------------------------------------------------------------------
# Beside the demo axes: an axis for DELETE /axes/{axis} to delete (so that the demo axes stay
# for the other operations) and cam tables (a new database has none). The path parameters
# below draw these names and ids most of the time, and anything the schema allows otherwise.
token=$("$venv/bin/python" - "$base" "$auth" <<'EOF'
import sys, requests
base = sys.argv[1] + "/api/v1"
h = {"Content-Type": "application/json"}
s = requests.Session()
if sys.argv[2] != "off":
    r = s.post(base + "/auth/login", json={"name": "st-admin", "password": "st-admin-password"}, headers=h, timeout=10)
    if r.status_code != 200:
        sys.exit(f"login: {r.status_code} {r.text}")
def post(path, body):
    r = s.post(base + path, json=body, headers=h, timeout=10)
    if r.status_code != 201:
        sys.exit(f"seeding {path} {body.get('name')}: {r.status_code} {r.text}")
config = s.get(base + "/axes/y", timeout=10).json()["config"]
post("/axes", dict(config, name="doomed"))
post("/cam-tables", {"name": "knife", "table_type": "motion_function", "periodic": True, "points": [
    {"point_index": 1, "function_type": "polynom1", "point_type": "velocity", "master_pos": 0.0, "slave_pos": 0.0, "slave_velo": 1.0},
    {"point_index": 2, "function_type": "polynom5_mm", "point_type": "velocity", "master_pos": 30.0, "slave_pos": 30.0, "slave_velo": 1.0},
    {"point_index": 3, "function_type": "polynom1", "point_type": "velocity", "master_pos": 330.0, "slave_pos": 330.0, "slave_velo": 1.0},
    {"point_index": 4, "function_type": "polynom1", "point_type": "velocity", "master_pos": 360.0, "slave_pos": 360.0, "slave_velo": 1.0}]})
post("/cam-tables", {"name": "rows", "table_type": "non_equidistant", "periodic": True,
                     "rows": [[0.0, 0.0], [180.0, 100.0], [360.0, 0.0]]})
post("/cam-tables", {"name": "doomed_table", "table_type": "non_equidistant",
                     "rows": [[0.0, 0.0], [10.0, 5.0]]})
if sys.argv[2] != "off":
    # Tokens 1-9 for DELETE /tokens/{id} to revoke; the run's own admin token after them.
    for i in range(1, 10):
        post("/tokens", {"name": f"decoy-{i}", "role": "viewer"})
    r = s.post(base + "/tokens", json={"name": "schemathesis", "role": "admin"}, headers=h, timeout=10)
    print(r.json()["token"])
EOF
)
auth_args=()
if [ "$auth" = admin ]; then
    auth_args=(--header "Authorization: Bearer $token")
fi

cat >"$work/schemathesis.toml" <<'EOF'
# No state kept between runs (a crash cache replayed first would change what a seed gives, and
# would be left in the work tree).
[cache]
enabled = false

# Path parameters: mostly names and ids that exist (demo axes x=1, y=2, spindle=3, the seeded
# axis doomed=4, cam tables knife=1, rows=2, doomed_table=3), otherwise whatever the schema
# allows (404s). Negative cases are generated as usual.
[dictionaries.axes]
values = ["x", "y", "spindle", "1", "2", "3"]
[dictionaries.doomed_axes]
values = ["doomed", "4"]
[dictionaries.tables]
values = ["knife", "rows", "1", "2"]
[dictionaries.doomed_tables]
values = ["doomed_table", "3"]
[dictionaries.parameters]
values = ["AxisTargetPositionWindow", "SWLimitPos", "AxisMaxVelocity", "AxisCtrlVelocityPreCtrlWeight", "CommandedPosition", "1", "2"]
[dictionaries.points]
values = [1, 2, 3]
[dictionaries.ids]
values = [1, 2, 3, 5, 8]
# A valid `?timeout_ms=` (with `wait=true`) holds the answer until the command reaches its
# milestone or that many ms pass (up to 10 min): valid values are drawn from these so that the
# run keeps its wall-clock bound. Invalid ones (over 600000, not a number) are generated as usual.
[dictionaries.timeouts]
values = [0, 1, 100, 2000]

[parameters]
"path.axis" = { dictionary = "axes", probability = 0.8 }
"path.table" = { dictionary = "tables", probability = 0.8 }
"path.parameter" = { dictionary = "parameters", probability = 0.8 }
"path.point" = { dictionary = "points", probability = 0.8 }
"path.id" = { dictionary = "ids", probability = 0.8 }
"query.timeout_ms" = { dictionary = "timeouts", probability = 1.0 }

# DELETE /tokens/{id} revokes only the decoy tokens, never the run's own (id 10).
[dictionaries.decoy_tokens]
values = ["1", "2", "3", "4", "5", "6", "7", "8", "9"]

[[operations]]
include-operation-id = "revoke_token"
parameters = { "path.id" = { dictionary = "decoy_tokens", probability = 1.0 } }

# Rules between fields that JSON Schema cannot state (named in each operation's description
# and docs/decisions.md): a schema-valid body may still be a 422 here — a modulo axis with
# software limits, a position table given points, a trigger channel beyond the channels, a
# master that is the slave itself, a move-modulo on a linear axis, a recording longer than
# 600 000 cycles, an X-Client-Id needed to take control while authentication is off, a group
# role the convention lacks, a default above the group's maximum, an arc that is no arc, a
# frame out of an XY group's plane, a conveyor that is a member or slower than the tracking,
# "ignore" or a value below 1 for a halt's deceleration, a path analysed for a group that is
# not there, a clock advance that gives none or several of cycles/seconds/until (or a bound
# without until) …
[[operations]]
include-operation-id = ["create_axis", "replace_axis", "import_config", "write_parameter",
    "create_cam_table", "replace_cam_table", "write_points", "write_point", "values",
    "master_position", "create_recording", "take_control", "gear_in", "gear_in_dyn", "cam_in",
    "cam_in_v2", "cam_add", "cam_exchange", "cam_remove", "cam_scaling", "cam_scaling_v2",
    "move_modulo", "jog", "home", "create_user", "update_user", "change_password", "create_token",
    "touch_probe", "put_setup", "analyse", "sdo_write", "inject_bus_fault", "phasing_absolute",
    "phasing_relative", "halt_phasing", "position_correction_limiter", "override_filter",
    "torque_control", "convert_pos_to_inc_pos", "ext_setpoint_gen_feed", "gear_in_multi_master",
    "create_group", "replace_group", "group_add_axis", "group_halt", "group_stop",
    "group_move_path", "group_set_coordinate_transform", "group_track_conveyor_belt",
    "analyse_path", "advance"]
checks.positive_data_acceptance.expected-statuses = ["2XX", "3XX", 401, 403, 404, 409, 422, 429, "5XX"]

[[operations]]
include-operation-id = "delete_axis"
parameters = { "path.axis" = { dictionary = "doomed_axes", probability = 0.8 } }

[[operations]]
include-operation-id = "delete_cam_table"
parameters = { "path.table" = { dictionary = "doomed_tables", probability = 0.8 } }

# DELETE /commands/{id} releases a command (the falling edge of Execute/Enable) and DELETE of an
# armed or running recording cancels it; both answer with the resource, which stays readable by
# design (documented). `use_after_free` assumes a DELETE removes what it names, so it does not
# apply to the GETs of these two resources.
[[operations]]
include-operation-id = ["get_command", "get_recording", "release_command", "delete_recording"]
checks.use_after_free.enabled = false
EOF

# --- The run -------------------------------------------------------------------------------
# Every state-changing request must say `Content-Type: application/json`, also one without a
# body (else 415 before routing, whatever the path or method): schemathesis sets it for the
# JSON bodies it generates, the header below also for the bodiless requests of its own checks
# (an undeclared method must be a 405, which only a request that passes the 415 check can get).
mkdir -p "$report_dir"
rm -f "$report_dir/events.ndjson" "$report_dir/junit.xml"
cmd=(
    "$venv/bin/st" --config-file "$work/schemathesis.toml" run "$base/openapi.json"
    --checks all
    --phases examples,coverage,fuzzing,stateful
    --max-examples "$max_examples"
    --seed "$seed"
    --generation-database none
    --workers "$workers"
    --continue-on-failure
    --exclude-path /api/v1/ws
    --request-timeout 30
    --header 'Content-Type: application/json'
    --report ndjson,junit
    --report-ndjson-path "$report_dir/events.ndjson"
    --report-junit-path "$report_dir/junit.xml"
    --no-color
    "${auth_args[@]}"
    "$@"
)
if [ "$auth" = off ]; then
    # Without users every request is served (loopback only): nothing expects a 401.
    cmd+=(--exclude-checks ignored_auth)
fi
say "$(printf "%q " "${cmd[@]}")"
start=$(date +%s)
set +e
timeout --signal=INT --kill-after=30 "$safety" "${cmd[@]}"
rc=$?
set -e
elapsed=$(($(date +%s) - start))

requests=$("$venv/bin/python" - "$report_dir/events.ndjson" <<'EOF'
import json, sys
n = 0
try:
    with open(sys.argv[1]) as f:
        for line in f:
            event = json.loads(line)
            finished = event.get("ScenarioFinished")
            if finished:
                n += len(finished["recorder"].get("interactions", {}))
except FileNotFoundError:
    pass
print(n)
EOF
)
say "$requests requests in ${elapsed} s (reports: $report_dir)"
if ! kill -0 "$server_pid" 2>/dev/null; then
    say "motiond died during the run:"; tail -n 50 "$work/server.log" >&2
    exit 1
fi
if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then
    say "the run made no end within the safety timeout of $safety s (ST_SAFETY_S): a hang, stopped"
    exit 1
fi
if [ "$rc" != 0 ]; then
    say "schemathesis failed (exit $rc)"
    exit "$rc"
fi
if [ "$requests" -lt "$min_requests" ]; then
    say "only $requests requests, fewer than $min_requests (ST_MIN_REQUESTS)"
    exit 1
fi
say "passed"
