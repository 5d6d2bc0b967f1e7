#!/usr/bin/env python3
"""The service's cycle compute time (docs/benchmarks.md): the demo machine idle (3 axes), 64
axes powered and standing, and 64 axes moving, from /metrics over a window, for one or more
motiond binaries measured alternately in one run.

Usage: cycle_service.py OUTDIR [--window S] NAME=MOTIOND [NAME=MOTIOND …]
"""
import json, os, sys, time

sys.argv, args = sys.argv[:1], sys.argv[1:]
out, rest = args[0], args[1:]
window = 10
if rest and rest[0] == "--window":
    window, rest = int(rest[1]), rest[2:]
binaries = [a.split("=", 1) for a in rest]
sys.argv = [sys.argv[0], binaries[0][1], "/bin/true", out, "--quick"]
import service  # noqa: E402


def measure(name, binary):
    service.MOTIOND = binary
    os.makedirs(out, exist_ok=True)
    log = open(os.path.join(out, f"motiond-{name}.log"), "w")
    proc, _ = service.start(["--db", ":memory:"], log)
    rows = {}
    try:
        time.sleep(2)
        m0 = service.metrics(); time.sleep(window); m1 = service.metrics()
        rows["idle_3_axes"] = service.window_quantiles(m0, m1, "motiond_cycle_compute_seconds")
        cfg = {"unit": "mm", "dynamics": {"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0,
                                           "jerk": 25000.0, "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0}}
        for i in range(61):
            st, body = service.http("POST", "/api/v1/axes", dict(cfg, name=f"a{i}"))
            assert st == 201, body
        names = ["x", "y", "spindle"] + [f"a{i}" for i in range(61)]
        for a in names:
            service.http("POST", f"/api/v1/axes/{a}/power?wait=true", {})
        time.sleep(1)
        m0 = service.metrics(); time.sleep(window); m1 = service.metrics()
        rows["standing_64_axes"] = service.window_quantiles(m0, m1, "motiond_cycle_compute_seconds")
        for a in names:
            service.http("POST", f"/api/v1/axes/{a}/move-velocity", {"velocity": 8.0 if a != "spindle" else 360.0})
        time.sleep(1)
        m0 = service.metrics(); time.sleep(window); m1 = service.metrics()
        rows["moving_64_axes"] = service.window_quantiles(m0, m1, "motiond_cycle_compute_seconds")
        rows["overruns_64"] = m1[1]["motiond_cycle_overruns_total"] - m0[1]["motiond_cycle_overruns_total"]
    finally:
        service.stop(proc)
    print(name, json.dumps(rows), flush=True)
    return rows


results = {"machine": service.machine(), "window_s": window, "runs": {n: measure(n, b) for n, b in binaries}}
json.dump(results, open(os.path.join(out, "cycle_service.json"), "w"), indent=1)
