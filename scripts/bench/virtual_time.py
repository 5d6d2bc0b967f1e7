#!/usr/bin/env python3
"""Virtual time (docs/benchmarks.md, "Virtual time"): cycles per second of wall time of
`motiond --clock virtual` advancing 60 s of machine time at 1 ms cycles — the demo machine
standing, its 3 axes moving, 64 axes moving — and the scenario folder's wall time.

Usage: virtual_time.py MOTIOND OUTDIR
"""
import glob, json, os, subprocess, sys, time

motiond, out = sys.argv[1], sys.argv[2]
sys.argv = [sys.argv[0], motiond, "/bin/true", out, "--quick"]
sys.path.insert(0, os.path.dirname(__file__))
import service  # noqa: E402

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def advance(body):
    st, r = service.http("POST", "/api/v1/clock/advance", body)
    assert st == 200, r
    return json.loads(r)


def command(path, body):
    st, r = service.http("POST", path, body)
    assert st == 202, r
    return json.loads(r)["id"]


def timed_minute():
    """Wall seconds for 60 s of machine time (60000 cycles of 1 ms), in 1 s advances."""
    t0 = time.monotonic()
    for _ in range(60):
        advance({"seconds": 1})
    return time.monotonic() - t0


def measure():
    os.makedirs(out, exist_ok=True)
    log = open(os.path.join(out, "motiond-virtual.log"), "w")
    proc, _ = service.start(["--db", ":memory:", "--clock", "virtual", "--control-lease", "false"], log)
    rows = {}
    try:
        rows["standing_3_axes_s"] = timed_minute()
        axes = ["x", "y", "spindle"]
        for a in axes:
            advance({"until": {"command": command(f"/api/v1/axes/{a}/power", {})}, "max_seconds": 1})
            command(f"/api/v1/axes/{a}/move-velocity", {"velocity": 8.0 if a != "spindle" else 360.0})
        rows["moving_3_axes_s"] = timed_minute()
        cfg = {"unit": "mm", "dynamics": {"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0,
                                           "jerk": 25000.0, "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0}}
        for i in range(61):
            st, body = service.http("POST", "/api/v1/axes", dict(cfg, name=f"a{i}"))
            assert st == 201, body
            advance({"until": {"command": command(f"/api/v1/axes/a{i}/power", {})}, "max_seconds": 1})
            command(f"/api/v1/axes/a{i}/move-velocity", {"velocity": 8.0})
        rows["moving_64_axes_s"] = timed_minute()
    finally:
        service.stop(proc)
    for k in list(rows):
        rows[k.replace("_s", "_x_real_time")] = round(60.0 / rows[k], 1)
        rows[k] = round(rows[k], 3)
    files = sorted(f for f in glob.glob(os.path.join(ROOT, "scenarios", "*.json")) if "schema" not in f)
    t0 = time.monotonic()
    r = subprocess.run([motiond, "scenario", "run"] + files, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rows["scenario_folder"] = {"files": len(files), "wall_s": round(time.monotonic() - t0, 3),
                               "summary": r.stdout.strip().splitlines()[-1]}
    return rows


results = {"machine": service.machine(), "virtual_time": measure()}
print(json.dumps(results, indent=1))
json.dump(results, open(os.path.join(out, "virtual_time.json"), "w"), indent=1)
