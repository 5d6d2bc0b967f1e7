"""What a benchmark ran on (machines of one size differ 2-3x, issue 27): the CPU model, the
load, and the machine-speed reference — the planner's cycle sample in ns, the planner bench's
`step`, timed by the load generator (`bench reference`, examples/bench.rs). Figures divided by
it travel between machines of one kind better than absolute ones."""
import os, subprocess


def describe(bench=None):
    model = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    out = {"cpu": model, "cpus": os.cpu_count(), "kernel": os.uname().release,
           "load_1min": os.getloadavg()[0], "planner_step_ns": None}
    if bench and os.path.exists(bench):
        r = subprocess.run([bench, "reference"], capture_output=True, text=True, check=True)
        out["planner_step_ns"] = float(r.stdout.strip())
    return out
