#!/usr/bin/env python3
"""Which parts of an axis a step touches (issue 27; the spans of
backend/motion/src/axis/prefetch.rs): runs the `axis_lines` example under valgrind's lackey
and maps every data access of ten steps of AXES axes to offsets in `Axis`. Prints the
touched byte ranges (merged when at most 16 bytes apart) and the cache lines per axis step.

    cargo build --release -p motion --example axis_lines
    python3 scripts/bench/axis_lines.py [AXES] [velocity|positioning|standing]
"""
import os
import subprocess
import sys
import tempfile

axes = sys.argv[1] if len(sys.argv) > 1 else "16"
load = sys.argv[2] if len(sys.argv) > 2 else "velocity"
binary = "target/release/examples/axis_lines"
with tempfile.TemporaryDirectory() as tmp:
    trace = os.path.join(tmp, "trace")
    run = subprocess.run(["valgrind", "--tool=lackey", "--trace-mem=yes", f"--log-file={trace}",
                          binary, axes, load], stderr=subprocess.PIPE, text=True, check=True)
    bases, size, marker = [], 0, None
    for line in run.stderr.splitlines():
        word = line.split()
        if word and word[0] == "axis":
            bases.append(int(word[1], 16))
            size = int(word[2])
        elif word and word[0] == "marker":
            marker = int(word[1], 16)
    touched, lines, marks = set(), set(), 0
    with open(trace) as f:
        for line in f:
            if not line.startswith(" "):
                continue
            kind, _, rest = line.strip().partition(" ")
            addr = int(rest.split(",")[0], 16)
            if addr == marker and kind == "L":
                marks += 1
                if marks == 2:
                    break
                continue
            if marks != 1:
                continue
            for base in bases:
                if base <= addr < base + size:
                    touched.add((addr - base) // 8 * 8)
                    lines.add(addr // 64)
                    break
if not bases or marks == 0:
    sys.exit("axis_lines.py: the example printed no axes or its marker was never read")
spans = []
for off in sorted(touched):
    if spans and off - spans[-1][1] <= 16:
        spans[-1][1] = off + 8
    else:
        spans.append([off, off + 8])
print(f"Axis: {size} bytes; {len(lines) / len(bases):.1f} of its cache lines touched per axis")
for start, end in spans:
    print(f"{start:6} .. {end:6}  ({end - start} bytes, lines {start // 64}..{(end - 1) // 64})")
