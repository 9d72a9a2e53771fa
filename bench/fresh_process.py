"""Whole-process timings of `pdeshape surface` at a given grid, one or more binaries run
alternately: the `--timings` line (solve, tessellate, weld, file, commit, total) and the wall
time measured here around the process, medians over the runs, with the output file's size.

    python3 bench/fresh_process.py RUNS DESIGN NU NV OUT.ext BINARY [BINARY ...]

Older binaries may print fewer timing keys; missing ones are left blank.
"""
import json
import os
import statistics
import subprocess
import sys
import time

runs, design, nu, nv, out = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5]
binaries = sys.argv[6:]
keys = ["solve_ms", "tessellate_ms", "weld_ms", "file_ms", "commit_ms", "write_ms", "total_ms"]
results = {b: [] for b in binaries}
for _ in range(runs):
    for b in binaries:
        t = time.perf_counter()
        p = subprocess.run(
            [b, "surface", design, "-o", out, "--nu", nu, "--nv", nv, "--timings", "--quiet"],
            capture_output=True,
            text=True,
        )
        wall = (time.perf_counter() - t) * 1e3
        if p.returncode != 0:
            sys.exit(f"{b}: {p.stderr}")
        line = [l for l in p.stderr.splitlines() if l.startswith("{")][-1]
        row = json.loads(line)
        row["wall_ms"] = wall
        row["bytes"] = os.path.getsize(out)
        results[b].append(row)
print(f"{runs} runs each, alternating; load average {os.getloadavg()[0]:.2f} at the end")
for b, rows in results.items():
    med = {k: statistics.median(r[k] for r in rows) for k in keys + ["wall_ms"] if k in rows[0]}
    size = rows[0]["bytes"]
    print(b, f"file {size / 1e6:.1f} MB")
    print("  " + "  ".join(f"{k} {med[k]:.1f}" for k in keys + ["wall_ms"] if k in med))
    if "write_ms" in med:
        print(f"  write {size / med['write_ms'] / 1e6:.2f} GB/s of file", end="")
        if "file_ms" in med:
            print(f"; weld + file (to close) {size / (med['weld_ms'] + med['file_ms']) / 1e6:.2f} GB/s", end="")
        print()
