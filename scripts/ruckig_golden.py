#!/usr/bin/env python3
"""Golden durations from upstream Ruckig for the planner's fidelity test.

Generates random 1-DoF problems from a fixed seed, solves each with the upstream C++ Ruckig
(PyPI `ruckig`, Python bindings over the C++ core) and writes the trajectory durations to
backend/motion/tests/golden/ruckig_durations.json, one problem per line.
backend/motion/tests/ruckig_golden.rs replays them through `Planner::plan_signed` (rsruckig).

    pip install ruckig==0.19.4      # pinned: the golden file records this version
    python3 scripts/ruckig_golden.py

Re-running regenerates the same file bit for bit (fixed seed, Python's `random` is specified
to be reproducible across platforms for `random()`, floats written with `repr`).

Problem kinds (see `KINDS`):
  rest    position interface, random state (|v| ≤ v_max, a within limits) → target, v_f = 0
  brake   like `rest` but |v0| above v_max (exercises Ruckig's brake pre-trajectory)
  vf      position interface with a non-zero target velocity (|v_f| ≤ v_max)
  vel     velocity interface to a random target velocity (some 0, some above v_max: the
          velocity interface does not limit velocity)
  invalid position interface with |v_f| > v_max: upstream rejects these at validation

Every input is rounded to 9 significant digits, so that its decimal form is short and any
JSON parser (serde_json's fast path included) reads back exactly the f64 solved here.
Target acceleration is always 0 (our planner never sets another); min_velocity is left unset
(= -max_velocity), as in the planner.
"""

import json
import math
import os
import random
import sys

UPSTREAM_VERSION = "0.19.4"
SEED = 20240917
COUNTS = {"rest": 1100, "brake": 300, "vf": 800, "vel": 700, "invalid": 100}

try:
    import ruckig
    from ruckig import ControlInterface, InputParameter, Result, Ruckig, RuckigError, Trajectory
except ImportError:
    sys.exit(f"needs upstream Ruckig: pip install ruckig=={UPSTREAM_VERSION}")

if ruckig.__version__ != UPSTREAM_VERSION:
    sys.exit(f"ruckig {ruckig.__version__} installed, the golden file is pinned to "
             f"{UPSTREAM_VERSION}: pip install ruckig=={UPSTREAM_VERSION}")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "backend", "motion", "tests", "golden", "ruckig_durations.json")


def r9(x):
    """Rounds to 9 significant digits (exactly representable round trip through JSON)."""
    return float(f"{x:.9g}") + 0.0  # + 0.0 turns -0.0 into 0.0


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def limits(rng):
    """Industrial limits spanning orders of magnitude, asymmetric acceleration."""
    vmax = r9(log_uniform(rng, 1.0, 5000.0))
    amax = r9(log_uniform(rng, 10.0, 1e5))
    # Deceleration differs from acceleration by up to a factor 5 either way.
    amin = -r9(min(max(amax * log_uniform(rng, 0.2, 5.0), 10.0), 1e5))
    # Jerk: ramping to amax takes 0.1 ms .. 1 s, jerk clipped to 1e2 .. 1e7.
    jmax = r9(min(max(amax / log_uniform(rng, 1e-4, 1.0), 100.0), 1e7))
    return vmax, amax, amin, jmax


def state(rng, vmax, amax, amin, above):
    p0 = 0.0 if rng.random() < 0.1 else r9(rng.uniform(-1000.0, 1000.0))
    if above:
        v0 = rng.choice([-1.0, 1.0]) * vmax * rng.uniform(1.01, 2.5)
    else:
        u = rng.random()
        v0 = 0.0 if u < 0.15 else (rng.choice([-1.0, 1.0]) * vmax if u < 0.2 else rng.uniform(-vmax, vmax))
    v0 = r9(v0)
    u = rng.random()
    if u < 0.3:
        a0 = 0.0
    elif u < 0.4:
        a0 = rng.choice([amin, amax])
    else:
        a0 = min(max(r9(rng.uniform(amin, amax)), amin), amax)
    return p0, v0, a0


def target_position(rng, p0, vmax):
    u = rng.random()
    if u < 0.03:
        return p0  # already there (possibly moving)
    # Travel time at v_max from 0.1 ms to 20 s, either direction.
    return r9(p0 + rng.choice([-1.0, 1.0]) * vmax * log_uniform(rng, 1e-4, 20.0))


def problem(rng, kind):
    vmax, amax, amin, jmax = limits(rng)
    p0, v0, a0 = state(rng, vmax, amax, amin, above=(kind == "brake"))
    pf = target_position(rng, p0, vmax)
    if kind in ("rest", "brake"):
        vf = 0.0
    elif kind == "vf":
        vf = r9(rng.choice([-1.0, 1.0]) * vmax * rng.uniform(0.01, 1.0))
    elif kind == "vel":
        u = rng.random()
        vf = 0.0 if u < 0.3 else r9(rng.uniform(-1.5, 1.5) * vmax)
        pf = 0.0  # ignored by the velocity interface
    elif kind == "invalid":
        vf = r9(rng.choice([-1.0, 1.0]) * vmax * rng.uniform(1.01, 2.0))
    else:
        raise ValueError(kind)
    return {
        "kind": kind,
        "interface": "velocity" if kind == "vel" else "position",
        "p0": p0, "v0": v0, "a0": a0, "pf": pf, "vf": vf,
        "vmax": vmax, "amax": amax, "amin": amin, "jmax": jmax,
    }


def solve(p):
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.control_interface = ControlInterface.Velocity if p["interface"] == "velocity" else ControlInterface.Position
    inp.current_position = [p["p0"]]
    inp.current_velocity = [p["v0"]]
    inp.current_acceleration = [p["a0"]]
    inp.target_position = [p["pf"]]
    inp.target_velocity = [p["vf"]]
    inp.target_acceleration = [0.0]
    inp.max_velocity = [p["vmax"]]
    inp.max_acceleration = [p["amax"]]
    inp.min_acceleration = [p["amin"]]
    inp.max_jerk = [p["jmax"]]
    traj = Trajectory(1)
    try:
        result = otg.calculate(inp, traj)
    except RuckigError as e:
        # The first line is the message; upstream appends a dump of the input.
        return None, str(e).strip().splitlines()[0].split(" input:")[0].strip()
    if result not in (Result.Working, Result.Finished):
        return None, str(result)
    return traj.duration, None


def main():
    rng = random.Random(SEED)
    problems = []
    for kind, n in COUNTS.items():
        for _ in range(n):
            problems.append(problem(rng, kind))
    rejected = 0
    for i, p in enumerate(problems):
        duration, reason = solve(p)
        p["id"] = i
        if duration is None:
            rejected += 1
            p["duration"] = None
            p["rejected"] = reason
        else:
            p["duration"] = duration
    keys = ["id", "kind", "interface", "p0", "v0", "a0", "pf", "vf",
            "vmax", "amax", "amin", "jmax", "duration", "rejected"]
    header = {
        "generator": "scripts/ruckig_golden.py",
        "upstream": {"package": "ruckig (PyPI, C++ core)", "version": ruckig.__version__},
        "seed": SEED,
        "counts": COUNTS,
        "rejected": rejected,
        "note": "1-DoF, target acceleration 0, min_velocity unset; durations in s; "
                "rejected problems have duration null and upstream's message",
    }
    lines = ["{"]
    for k, v in header.items():
        lines.append(f"  {json.dumps(k)}: {json.dumps(v)},")
    lines.append('  "problems": [')
    body = []
    for p in problems:
        body.append("    " + json.dumps({k: p[k] for k in keys if k in p}, separators=(",", ":")))
    lines.append(",\n".join(body))
    lines.append("  ]")
    lines.append("}")
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w", encoding="utf-8", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {len(problems)} problems ({rejected} rejected by upstream ruckig "
          f"{ruckig.__version__}) to {os.path.relpath(OUT, ROOT)}")


if __name__ == "__main__":
    main()
