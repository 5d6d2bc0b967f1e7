#!/usr/bin/env python3
"""Cycle figures with each drive bus, in one run (issue 11): motiond on the simulated bus, on
the emulated EtherCAT segment (in-process), and on a veth pair (`--bus ethercat` against
`motiond emulate-segment`, inside a network namespace), each with x and y moving back and
forth for WINDOW seconds. Prints a Markdown table and writes the raw figures as JSON.

    python3 scripts/bench/bus.py target/release/motiond OUT_DIR [WINDOW_S]

The veth row needs root (it re-runs itself under `unshare -n`); without it the row says so.
"""
import json
import os
import subprocess
import sys
import time
import urllib.error
import urllib.request

BIN, OUT = sys.argv[1], sys.argv[2]
WINDOW = float(sys.argv[3]) if len(sys.argv) > 3 else 20.0
PORT = 18731


def call(method, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(f"http://127.0.0.1:{PORT}{path}", data=data, method=method,
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=30) as r:
        return json.loads(r.read() or b"null")


def wait_up(p):
    for _ in range(600):
        try:
            return call("GET", "/api/v1/system")
        except Exception:
            if p.poll() is not None:
                raise SystemExit(f"motiond ended: {p.returncode}")
            time.sleep(0.05)
    raise SystemExit("motiond did not come up")


def measure(mode, extra):
    p = subprocess.Popen([BIN, "--db", ":memory:", "--listen", f"127.0.0.1:{PORT}",
                          "--control-lease", "false", *extra],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_up(p)
        axes = ["x", "y"]
        if mode == "veth":
            # Axes on the segment's drives (the demo axes stay simulated on --bus ethercat).
            for i, name in enumerate(["ex", "ey"]):
                cfg = call("GET", "/api/v1/axes/y")["config"]
                cfg.update(name=name, soft_limits=None,
                           drive={"kind": "cia402", "subdevice": i, "increments_per_unit": 1000.0})
                call("POST", "/api/v1/axes", cfg)
            axes = ["ex", "ey"]
        for a in axes:
            call("POST", f"/api/v1/axes/{a}/power", {"enable": True})
        for a in axes:
            deadline = time.time() + 10
            while not call("GET", f"/api/v1/axes/{a}/status")["status"]["power_status"]:
                if time.time() > deadline:
                    raise SystemExit(f"{a} did not power on")
                time.sleep(0.02)
        before = call("GET", "/api/v1/system")["timing"]
        end = time.time() + WINDOW
        target = 200.0
        stops = []
        while time.time() < end:
            for a in axes:
                try:
                    call("POST", f"/api/v1/axes/{a}/move-absolute?wait=true&timeout_ms=20000",
                         {"position": target, "velocity": 400.0})
                except urllib.error.HTTPError as e:
                    # The axis was stopped (bus_error after lost frames): note why, reset, go on.
                    st = call("GET", f"/api/v1/axes/{a}/status")["status"]
                    stops.append({"axis": a, "http": e.code, "error_id": st["error_id"]})
                    call("POST", f"/api/v1/axes/{a}/reset?wait=true&timeout_ms=5000", {})
                    time.sleep(0.05)
            target = 20.0 if target > 100 else 200.0
        sysinfo = call("GET", "/api/v1/system")
        bus = call("GET", "/api/v1/bus")
        t = sysinfo["timing"]
        return {"mode": mode, "cycles": t["cycles"] - before["cycles"], "stops": stops,
                "overruns": t["overruns"] - before["overruns"],
                "wakeup_latency": t["wakeup_latency"], "compute": t["compute"], "period": t["period"],
                "bus": {k: bus.get(k) for k in ["kind", "state", "frames", "lost_frames",
                                                 "working_counter_errors", "dc_cycle_offset_ns"]},
                "realtime": sysinfo["realtime"]}
    finally:
        p.terminate()
        p.wait()


def veth():
    for args in (["link", "set", "lo", "up"], ["link", "add", "ecA", "type", "veth", "peer", "name", "ecB"],
                 ["link", "set", "ecA", "up"], ["link", "set", "ecB", "up"]):
        subprocess.run(["ip", *args], check=True)
    emu = subprocess.Popen([BIN, "emulate-segment", "--on", "ecB", "--drives", "2"],
                           stdout=subprocess.DEVNULL)
    try:
        return measure("veth", ["--bus", "ethercat", "--interface", "ecA"])
    finally:
        emu.terminate()
        emu.wait()


if len(sys.argv) > 4 and sys.argv[4] == "--veth-only":
    print(json.dumps(veth()))
    sys.exit(0)

os.makedirs(OUT, exist_ok=True)
rows = [measure("simulated", []), measure("emulated", ["--bus", "emulated"])]
r = subprocess.run(["unshare", "-n", sys.executable, __file__, BIN, OUT, str(WINDOW), "--veth-only"],
                   capture_output=True, text=True)
if r.returncode == 0:
    rows.append(json.loads(r.stdout.strip().splitlines()[-1]))
else:
    print(f"veth row skipped (needs root and network namespaces): {r.stderr.strip()[-300:]}")
with open(os.path.join(OUT, "bus.json"), "w") as f:
    json.dump(rows, f, indent=1)
print("| bus | cycles | overruns | wake-up p50 / p99 / max µs | compute p50 / p99 / max µs | lost frames | axes stopped | DC offset µs |")
print("|---|---|---|---|---|---|---|---|")
for x in rows:
    w, c, b = x["wakeup_latency"], x["compute"], x["bus"]
    off = b.get("dc_cycle_offset_ns")
    print(f"| {x['mode']} | {x['cycles']} | {x['overruns']} | {w['p50_us']:.1f} / {w['p99_us']:.1f} / {w['max_us']:.0f} "
          f"| {c['p50_us']:.1f} / {c['p99_us']:.1f} / {c['max_us']:.0f} | {b.get('lost_frames', 0) or 0} "
          f"| {len(x['stops'])} | {'—' if off is None else f'{off / 1000:.0f}'} |")
