#!/usr/bin/env python3
"""The kernel's per-axis step cost, then and now, in one run (docs/benchmarks.md, "Kernel
cycle"; issue 27): `backend/motion/benches/axis_cost.rs` built from this tree and from an older
commit (default 0ec0f4a, before the blocks of issues 9, 24 and 26), the two binaries run
alternately (then, now, then, now), each result divided by the machine-speed reference (the
planner's cycle sample, `reference/planner_step`, measured in the same binaries).

Usage: kernel_then_now.py OUTDIR [--commit C] [--measurement-time S] [--filter REGEX]
Needs git and cargo; the old tree goes to OUTDIR/src (a git worktree), its build to
OUTDIR/target.
"""
import argparse, json, os, re, subprocess, sys

sys.path.insert(0, os.path.dirname(__file__))
import machine_info  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

ap = argparse.ArgumentParser()
ap.add_argument("out")
ap.add_argument("--commit", default="0ec0f4a")
ap.add_argument("--measurement-time", default="3")
ap.add_argument("--filter", default="")
a = ap.parse_args()
out = os.path.abspath(a.out)
os.makedirs(out, exist_ok=True)


def sh(*cmd, cwd=ROOT, env=None):
    return subprocess.run(cmd, cwd=cwd, env=env, check=True, capture_output=True, text=True).stdout


def old_tree():
    """A worktree of the old commit with the bench added (patched to its API)."""
    src = os.path.join(out, "src")
    if not os.path.exists(src):
        sh("git", "worktree", "add", "--detach", src, a.commit)
    bench = open(os.path.join(ROOT, "backend/motion/benches/axis_cost.rs")).read()
    if "buffer_mode" not in sh("git", "show", f"{a.commit}:backend/motion/src/command.rs").split("Power {", 1)[1].split("}", 1)[0]:
        # Before MC_Power had a BufferMode, and before commands named a group or an axis.
        bench = bench.replace("override_percent: 100.0,\n                    buffer_mode: BufferMode::Aborting,",
                              "override_percent: 100.0,")
    if "target: Target" not in sh("git", "show", f"{a.commit}:backend/motion/src/command.rs"):
        bench = bench.replace("target: Target::Axis(axis),", "axis,")
    open(os.path.join(src, "backend/motion/benches/axis_cost.rs"), "w").write(bench)
    toml = os.path.join(src, "backend/motion/Cargo.toml")
    t = open(toml).read()
    if 'name = "axis_cost"' not in t:
        open(toml, "a").write('\n[[bench]]\nname = "axis_cost"\nharness = false\n')
    return src


def build(src, target):
    env = dict(os.environ, CARGO_TARGET_DIR=target)
    msgs = sh("cargo", "bench", "-p", "motion", "--bench", "axis_cost", "--no-run",
              "--message-format=json", cwd=src, env=env)
    for line in msgs.splitlines():
        m = json.loads(line)
        if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "axis_cost" and m.get("executable"):
            return m["executable"]
    raise SystemExit("no axis_cost executable built in " + src)


def run(binary):
    """{bench id: median ns} of one run of the bench binary."""
    args = [binary, "--bench", "--noplot", "--measurement-time", a.measurement_time, "--warm-up-time", "1"]
    if a.filter:
        args.append(a.filter)
    text = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    res, name = {}, None
    unit = {"ps": 1e-3, "ns": 1.0, "µs": 1e3, "us": 1e3, "ms": 1e6, "s": 1e9}
    for line in text.splitlines():
        m = re.match(r"^(\S+)\s*(time:.*)?$", line)
        if m and not line.startswith(" ") and not line.startswith("Benchmarking") and "/" in m.group(1):
            name = m.group(1)
        t = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+) \S+ \S+\]", line)
        if t and name:
            res[name] = float(t.group(1)) * unit[t.group(2)]
            name = None
    return res


now_bin = build(ROOT, os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")))
then_bin = build(old_tree(), os.path.join(out, "target"))
machine = machine_info.describe()  # the reference is measured by the bench itself
runs = []
for label, binary in [("then", then_bin), ("now", now_bin), ("then", then_bin), ("now", now_bin)]:
    r = run(binary)
    print(label, json.dumps(r), flush=True)
    runs.append((label, r))

ref = min(r["reference/planner_step"] for label, r in runs if label == "now")
machine["planner_step_ns"] = ref
rows = {}
for label, r in runs:
    for k, v in r.items():
        m = re.match(r"axis_cost_(\w+)/(\d+)", k)
        if m:
            per_axis = v / int(m.group(2))
            rows.setdefault(k, {}).setdefault(label, []).append(per_axis)
print(f"\nmachine: {machine}\nper axis, ns (run 1 / run 2), and ÷ planner step ({ref:.1f} ns):")
print("| case | then | now | now ÷ then | now ÷ planner step |")
print("|---|---|---|---|---|")
for k, v in rows.items():
    t, n = v.get("then", []), v.get("now", [])
    fmt = lambda xs: " / ".join(f"{x:.1f}" for x in xs)
    ratio = (min(n) / min(t)) if t and n else float("nan")
    print(f"| {k} | {fmt(t)} | {fmt(n)} | {ratio:.2f} | {min(n) / ref:.2f} |")
for case in sorted({re.match(r"axis_cost_(\w+)/", k).group(1) for k in rows}):
    small, big = rows.get(f"axis_cost_{case}/16", {}), rows.get(f"axis_cost_{case}/256", {})
    if small.get("now") and big.get("now"):
        print(f"{case}: 256 ÷ 16 per axis: now {min(big['now']) / min(small['now']):.2f}"
              + (f", then {min(big['then']) / min(small['then']):.2f}" if small.get("then") else ""))
json.dump({"machine": machine, "commit_then": a.commit, "runs": runs, "per_axis_ns": rows},
          open(os.path.join(out, "kernel_then_now.json"), "w"), indent=1)
