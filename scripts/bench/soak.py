#!/usr/bin/env python3
"""Memory soak of motiond (issue "Security and reliability": is memory bounded under load?).

For MINUTES minutes against a release motiond with a database file: 20 motion commands and
20 reads per second over HTTP (keep-alive and new connections), 50 websocket clients that
reconnect every 10 s with 3 axis subscriptions at 50 Hz, and every 2 minutes a burst of 1000
websocket clients for 10 s. RSS is sampled every 10 s; the result (start, peak, end, slope of
the second half in MB/min) goes to OUT/soak.json and is printed.

Usage: soak.py MOTIOND BENCH OUTDIR [MINUTES]   (scripts/bench/run.sh builds both binaries)
"""
import json, os, resource, subprocess, sys, threading, time, urllib.request

MOTIOND, BENCH, OUT = sys.argv[1], sys.argv[2], sys.argv[3]
MINUTES = float(sys.argv[4]) if len(sys.argv) > 4 else 10.0
PORT = 18191
BASE = f"http://127.0.0.1:{PORT}"
_hard = resource.getrlimit(resource.RLIMIT_NOFILE)[1]
resource.setrlimit(resource.RLIMIT_NOFILE, (_hard if _hard != resource.RLIM_INFINITY else 65536, _hard))


def http(method, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(BASE + path, data=data, method=method, headers={"content-type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def rss_mb(pid):
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmRSS"):
            return int(line.split()[1]) / 1024


def main():
    os.makedirs(OUT, exist_ok=True)
    db = os.path.join(OUT, "soak.db")
    for f in (db, db + "-wal", db + "-shm"):
        if os.path.exists(f):
            os.remove(f)
    log = open(os.path.join(OUT, "soak-motiond.log"), "w")
    proc = subprocess.Popen([MOTIOND, "--db", db, "--listen", f"127.0.0.1:{PORT}", "--max-connections", "4000"],
                            stdout=log, stderr=subprocess.STDOUT)
    for _ in range(500):
        try:
            if http("GET", "/api/v1/system")[0] == 200:
                break
        except Exception:
            time.sleep(0.01)
    for a in ("x", "y", "spindle"):
        http("POST", f"/api/v1/axes/{a}/power?wait=true", {})
    end = time.time() + MINUTES * 60
    stop = threading.Event()
    errors = {"http": 0}

    def commands():
        sign = 1
        while not stop.is_set():
            t = time.time()
            for _ in range(20):
                st, _ = http("POST", "/api/v1/axes/x/move-relative", {"distance": 5.0 * sign, "velocity": 400.0})
                sign = -sign
                errors["http"] += st >= 500
                http("GET", "/api/v1/axes/y/status")
            time.sleep(max(0.0, 1.0 - (time.time() - t)))

    def sockets():
        while not stop.is_set():
            subprocess.run([BENCH, "ws", f"127.0.0.1:{PORT}", "50", "50", "10", "x", "y", "spindle"], capture_output=True)

    def bursts():
        while not stop.wait(120):
            subprocess.run([BENCH, "ws", f"127.0.0.1:{PORT}", "1000", "10", "10", "x"], capture_output=True)

    threads = [threading.Thread(target=f, daemon=True) for f in (commands, sockets, bursts)]
    for t in threads:
        t.start()
    t0 = time.time()
    samples = []
    while time.time() < end:
        samples.append((round(time.time() - t0), round(rss_mb(proc.pid), 1)))
        print("rss", samples[-1], flush=True)
        time.sleep(10)
    stop.set()
    for t in threads:
        t.join(timeout=30)
    time.sleep(5)
    samples.append((round(time.time() - t0), round(rss_mb(proc.pid), 1)))
    proc.terminate()
    proc.wait()
    half = [s for s in samples if s[0] >= samples[-1][0] / 2]
    n = len(half)
    mx = sum(s[0] for s in half) / n
    my = sum(s[1] for s in half) / n
    slope = sum((s[0] - mx) * (s[1] - my) for s in half) / max(1e-9, sum((s[0] - mx) ** 2 for s in half)) * 60
    result = {"minutes": MINUTES, "rss_start_mb": samples[0][1], "rss_peak_mb": max(s[1] for s in samples),
              "rss_end_mb": samples[-1][1], "slope_second_half_mb_per_min": round(slope, 3),
              "http_5xx": errors["http"], "samples": samples}
    json.dump(result, open(os.path.join(OUT, "soak.json"), "w"), indent=2)
    print("soak", json.dumps({k: v for k, v in result.items() if k != "samples"}), flush=True)


main()
