#!/usr/bin/env python3
"""The websocket feed's curve (docs/benchmarks.md, "Websocket feed"): websocket clients × moving
axes at 50 Hz → updates delivered / asked and motiond's CPU, for one or more motiond binaries
measured alternately in one run (before/after on the same machine at the same time).

Usage: feed.py BENCH OUTDIR [--window S] [--cases 100x64,200x64] NAME=MOTIOND [NAME=MOTIOND …]
BENCH is target/release/examples/bench (its `ws` mode is the load generator). Name a binary
more than once (old=A new=B old2=A new2=B …) to alternate them.
"""
import json, os, sys, time

sys.argv, args = sys.argv[:1], sys.argv[1:]
bench, out = args[0], args[1]
rest = args[2:]
window = 10
cases = None
while rest and rest[0] in ("--window", "--cases"):
    if rest[0] == "--window":
        window = int(rest[1])
    else:
        cases = [tuple(int(x) for x in c.split("x")) for c in rest[1].split(",")]
    rest = rest[2:]
binaries = [a.split("=", 1) for a in rest]
sys.argv = [sys.argv[0], binaries[0][1], bench, out, "--quick"]
import service  # noqa: E402  (reads MOTIOND, BENCH, OUT from argv)

service.WINDOW = window
CASES = cases or [(100, 16), (100, 32), (100, 48), (100, 64), (10, 64), (200, 64)]


def messages():
    """(made, shared) tick messages from /metrics, or None where motiond does not count them."""
    c = service.metrics()[1]
    made, shared = c.get("motiond_ws_messages_made_total"), c.get("motiond_ws_messages_shared_total")
    return None if made is None or shared is None else (made, shared)


def curve(name, binary):
    service.MOTIOND = binary
    os.makedirs(out, exist_ok=True)
    log = open(os.path.join(out, f"motiond-{name}.log"), "w")
    proc, _ = service.start(["--db", ":memory:", "--max-connections", "4000"], log)
    cfg = {"unit": "mm", "dynamics": {"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0,
                                       "jerk": 25000.0, "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0}}
    axes = ["x", "y", "spindle"]
    rows = []
    try:
        for clients, n in CASES:
            while len(axes) < n:
                a = f"a{len(axes)}"
                st, body = service.http("POST", "/api/v1/axes", dict(cfg, name=a))
                assert st == 201, body
                axes.append(a)
                st, body = service.http("POST", f"/api/v1/axes/{a}/power?wait=true", {})
                assert st == 202, body
                st, body = service.http("POST", f"/api/v1/axes/{a}/move-velocity", {"velocity": 8.0})
                assert st == 202, body
            for a in ("x", "y", "spindle"):
                service.http("POST", f"/api/v1/axes/{a}/power?wait=true", {})
                service.http("POST", f"/api/v1/axes/{a}/move-velocity", {"velocity": 8.0 if a != "spindle" else 360.0})
            time.sleep(1)
            before = messages()
            ws = service.ws_load(proc, f"{name} {clients}x{n}", clients, axes[:n])
            after = messages()
            asked = clients * n * 50
            row = {"clients": clients, "axes": n, "asked_per_s": asked, "delivered_per_s": ws["updates_per_s"],
                   "delivered_fraction": round(ws["updates_per_s"] / asked, 3),
                   "motiond_cpu_percent": ws["motiond_cpu_percent"], "overruns": ws["overruns"],
                   "mb_per_s": ws["mb_per_s"], "motiond_cpu_percent_by_thread": ws["motiond_cpu_percent_by_thread"]}
            if before and after:
                # Tick messages made by a socket and taken from another's (motiond from 1f46409 on).
                made, shared = after[0] - before[0], after[1] - before[1]
                row["messages_shared_fraction"] = round(shared / max(made + shared, 1), 3)
            rows.append(row)
    finally:
        service.stop(proc)
    return rows


def main():
    results = {"machine": service.machine(), "window_s": window, "runs": {}}
    for name, binary in binaries:
        results["runs"][name] = curve(name, binary)
    path = os.path.join(out, "feed.json")
    json.dump(results, open(path, "w"), indent=1)
    print(json.dumps(results, indent=1))
    print(f"results: {path}")


main()
