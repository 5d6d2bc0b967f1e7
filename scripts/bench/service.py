#!/usr/bin/env python3
"""Service benchmarks of motiond (figures for docs/benchmarks.md, section "Service").

1. Wake-up latency of the idle cycle thread over a window (from /metrics deltas).
2. POST move-absolute -> 202 round trip at 1 kHz cycle (examples/bench.rs rtt).
3. 100 websocket clients x 16 axes at 50 Hz while all axes move: overruns and CPU.
4. The same with 64 moving axes, and 1000 clients x 4 axes.
5. POST -> 202 at a 250 us cycle (another motiond).
6. Footprint: ready time and RSS of motiond restarted on a database with 64 axes; /metrics size.
7. cyclictest (Debian rt-tests) on the same CPU, priority and interval, same run.

Usage: service.py MOTIOND BENCH OUTDIR [--quick]
"""
import json, os, re, resource, subprocess, sys, time, urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import machine_info  # noqa: E402

MOTIOND, BENCH, OUT = sys.argv[1], sys.argv[2], sys.argv[3]
QUICK = "--quick" in sys.argv
WINDOW = 10 if QUICK else 30
PORT = 18181
BASE = f"http://127.0.0.1:{PORT}"
# 1000 websocket clients: motiond and the load generator each hold ~1000 sockets.
_hard = resource.getrlimit(resource.RLIMIT_NOFILE)[1]
resource.setrlimit(resource.RLIMIT_NOFILE, (_hard if _hard != resource.RLIM_INFINITY else 65536, _hard))
TICK = os.sysconf("SC_CLK_TCK")


def http(method, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(BASE + path, data=data, method=method, headers={"content-type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, r.read().decode()
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode()


def metrics():
    _, text = http("GET", "/metrics?buckets=fine")
    hist, counters = {}, {}
    for line in text.splitlines():
        m = re.match(r'(\w+)_bucket\{le="([^"]+)"\} (\d+)', line)
        if m:
            hist.setdefault(m.group(1), []).append((float("inf") if m.group(2) == "+Inf" else float(m.group(2)), int(m.group(3))))
            continue
        m = re.match(r"(\w+) ([0-9.e+-]+)$", line)
        if m:
            counters[m.group(1)] = float(m.group(2))
    return hist, counters


def window_quantiles(before, after, name):
    """p50/p99/max (µs, bucket upper bounds) of the samples between two scrapes."""
    b = dict(before[0][name]); a = after[0][name]
    cum = [(le, n - b.get(le, 0)) for le, n in a]
    total = cum[-1][1]
    res = {"count": total}
    for q, key in ((0.5, "p50_us"), (0.99, "p99_us"), (0.999, "p999_us")):
        rank = max(1, int(q * total + 0.999999))
        res[key] = next(round(le * 1e6, 1) for le, n in cum if n >= rank)
    prev = 0
    mx = 0
    for le, n in cum:
        if n > prev and le != float("inf"):
            mx = le
        prev = n
    res["max_us_bucket_upper"] = round(mx * 1e6, 1)
    return res


def machine(bench=None):
    """What the figures were measured on, with the machine-speed reference (machine.py)."""
    bench = bench or BENCH
    if not os.path.exists(bench) or bench == "/bin/true":
        # The load generator beside the binary (target/release/examples/bench).
        bench = os.path.join(os.path.dirname(MOTIOND), "examples", "bench")
    return machine_info.describe(bench)


def cpu_ticks(pid):
    """(process utime+stime, {thread name: ticks})."""
    def ticks(path):
        f = open(path).read().rsplit(")", 1)[1].split()
        return int(f[11]) + int(f[12])
    threads = {}
    for t in os.listdir(f"/proc/{pid}/task"):
        name = open(f"/proc/{pid}/task/{t}/comm").read().strip()
        threads[name] = threads.get(name, 0) + ticks(f"/proc/{pid}/task/{t}/stat")
    return ticks(f"/proc/{pid}/stat"), threads


def start(args, log):
    """motiond on PORT with `args`; returns (process, seconds until /api/v1/system answered)."""
    t0 = time.monotonic()
    proc = subprocess.Popen([MOTIOND, "--listen", f"127.0.0.1:{PORT}"] + args, stdout=log, stderr=subprocess.STDOUT)
    while True:
        try:
            if http("GET", "/api/v1/system")[0] == 200:
                return proc, time.monotonic() - t0
        except Exception:
            time.sleep(0.002)
        assert proc.poll() is None, "motiond ended"


def stop(proc):
    proc.terminate()
    proc.wait()


def rss_mb(proc):
    for line in open(f"/proc/{proc.pid}/status"):
        if line.startswith("VmRSS"):
            return round(int(line.split()[1]) / 1024, 1)


def ws_load(proc, name, clients, axes):
    """`clients` websocket clients on `axes` at 50 Hz for WINDOW s: updates, CPU, overruns."""
    m0 = metrics(); c0 = cpu_ticks(proc.pid); t0 = time.time(); ch0 = os.times()
    out = subprocess.run([BENCH, "ws", f"127.0.0.1:{PORT}", str(clients), "50", str(WINDOW)] + axes, capture_output=True, text=True, check=True).stdout
    ch1 = os.times(); t1 = time.time(); c1 = cpu_ticks(proc.pid); m1 = metrics()
    el = t1 - t0
    ws = json.loads(out)
    ws["overruns"] = m1[1]["motiond_cycle_overruns_total"] - m0[1]["motiond_cycle_overruns_total"]
    ws["wakeup_latency"] = window_quantiles(m0, m1, "motiond_cycle_wakeup_latency_seconds")
    ws["compute"] = window_quantiles(m0, m1, "motiond_cycle_compute_seconds")
    ws["motiond_cpu_percent"] = round(100 * (c1[0] - c0[0]) / TICK / el, 1)
    ws["motiond_cpu_percent_by_thread"] = {k: round(100 * (v - c0[1].get(k, 0)) / TICK / el, 1) for k, v in c1[1].items()}
    ws["load_generator_cpu_percent"] = round(100 * ((ch1.children_user - ch0.children_user) + (ch1.children_system - ch0.children_system)) / el, 1)
    print(name, json.dumps(ws), flush=True)
    return ws


def rtt(n):
    st, body = http("POST", "/api/v1/axes/y/power?wait=true", {})
    assert st == 202, body
    m0 = metrics()
    out = subprocess.run([BENCH, "rtt", BASE, str(n)], capture_output=True, text=True, check=True).stdout
    m1 = metrics()
    r = json.loads(out)
    r["overruns"] = m1[1]["motiond_cycle_overruns_total"] - m0[1]["motiond_cycle_overruns_total"]
    return r


def main():
    os.makedirs(OUT, exist_ok=True)
    log = open(os.path.join(OUT, "motiond.log"), "w")
    db = os.path.join(OUT, "bench.db")
    for f in (db, db + "-wal", db + "-shm"):
        if os.path.exists(f):
            os.remove(f)
    proc, _ = start(["--db", db, "--max-connections", "4000"], log)
    results = {"machine": machine()}
    try:
        system = json.loads(http("GET", "/api/v1/system")[1])
        results["realtime"] = system["realtime"]
        time.sleep(2)  # start-up done
        results["metrics_bytes_demo"] = len(http("GET", "/metrics")[1].encode())

        # 1. idle wake-up latency
        m0 = metrics(); time.sleep(WINDOW); m1 = metrics()
        results["idle"] = {
            "seconds": WINDOW,
            "wakeup_latency": window_quantiles(m0, m1, "motiond_cycle_wakeup_latency_seconds"),
            "compute": window_quantiles(m0, m1, "motiond_cycle_compute_seconds"),
            "overruns": m1[1]["motiond_cycle_overruns_total"] - m0[1]["motiond_cycle_overruns_total"],
        }
        print("idle", json.dumps(results["idle"]), flush=True)

        # 2. POST -> 202 round trip
        results["rtt"] = rtt(2000 if QUICK else 10000)
        print("rtt", json.dumps(results["rtt"]), flush=True)

        # 3. 16 moving axes, 100 websocket clients at 50 Hz each on all 16; 4. 64 axes, and
        # 1000 clients on 4 of them
        axes = ["x", "y", "spindle"]
        cfg = {"unit": "mm", "dynamics": {"max_velocity": 500.0, "acceleration": 2500.0, "deceleration": 2500.0, "jerk": 25000.0, "jog_velocity_slow": 10.0, "jog_velocity_fast": 100.0}}

        def add_moving(n):
            for i in range(len(axes) - 3, len(axes) - 3 + n):
                st, body = http("POST", "/api/v1/axes", dict(cfg, name=f"a{i}"))
                assert st == 201, body
                axes.append(f"a{i}")
            for a in axes:
                st, body = http("POST", f"/api/v1/axes/{a}/power?wait=true", {})
                assert st == 202, body
                st, body = http("POST", f"/api/v1/axes/{a}/move-velocity", {"velocity": 8.0 if a != "spindle" else 360.0})
                assert st == 202, body
            time.sleep(1)

        add_moving(13)
        results["ws"] = ws_load(proc, "ws", 100, axes)
        add_moving(48)
        results["ws64"] = ws_load(proc, "ws64", 100, axes)
        results["ws1000x4"] = ws_load(proc, "ws1000x4", 1000, axes[:4])
    finally:
        stop(proc)

    # 5. POST -> 202 at a 250 us cycle, with the database in memory and in a file (the
    # submission's audit row is committed, fsync and all, before the 202)
    for key, dbarg in (("rtt_250us_memory", ":memory:"), ("rtt_250us_file", os.path.join(OUT, "bench250.db"))):
        for f in (dbarg, dbarg + "-wal", dbarg + "-shm"):
            if f != ":memory:" and os.path.exists(f):
                os.remove(f)
        proc, _ = start(["--db", dbarg, "--cycle-us", "250"], log)
        try:
            time.sleep(1)
            results[key] = rtt(2000 if QUICK else 10000)
            print(key, json.dumps(results[key]), flush=True)
        finally:
            stop(proc)

    # 6. Footprint with the 64 axes stored
    runs = []
    for _ in range(3):
        proc, ready = start(["--db", db], log)
        time.sleep(2)
        runs.append({"ready_ms": round(ready * 1000), "rss_mb": rss_mb(proc)})
        stop(proc)
    results["footprint_64_axes"] = runs
    print("footprint_64_axes", json.dumps(runs), flush=True)

    # 7. cyclictest, same CPU / priority / interval, after motiond has stopped
    cpu = results["realtime"].get("pinned_cpu")
    loops = WINDOW * 1000
    hist = os.path.join(OUT, "cyclictest.hist")
    cmd = ["cyclictest", "-m", "-q", "-p", "80", "-t", "1", "-i", "1000", "-l", str(loops), "-h", "20000", f"--histfile={hist}"]
    if cpu is not None:
        cmd += ["-a", str(cpu)]
    subprocess.run(cmd, check=True, capture_output=True)
    counts = []
    for line in open(hist):
        if line.startswith("#"):
            continue
        parts = line.split()
        if len(parts) >= 2:
            counts.append((int(parts[0]), int(parts[1])))
    total = sum(n for _, n in counts)
    mx = max(v for v, n in counts if n > 0)
    overflow = re.search(r"# Histogram Overflows: (\d+)", open(hist).read())
    def q(p):
        rank = max(1, int(p * total + 0.999999)); acc = 0
        for v, n in counts:
            acc += n
            if acc >= rank:
                return v + 1  # bucket [v, v+1) µs: upper bound, as for motiond
        return mx
    results["cyclictest"] = {"count": total, "p50_us": q(0.5), "p99_us": q(0.99), "p999_us": q(0.999), "max_us": mx,
                             "overflows": int(overflow.group(1)) if overflow else 0, "command": " ".join(cmd)}
    print("cyclictest", json.dumps(results["cyclictest"]), flush=True)
    json.dump(results, open(os.path.join(OUT, "results.json"), "w"), indent=2)


if __name__ == "__main__":
    main()
