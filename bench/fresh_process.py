"""Whole-process timings of `pdeshape surface` (or `pdeshape blend`, with `--blend` first) at
a given grid, one or more binaries run alternately: the `--timings` line (solve, tessellate,
weld, file, commit, total) and the wall time measured here around the process, medians over the
runs, with the output file's size, and the user and system CPU time of the process.

    python3 bench/fresh_process.py [--blend] [--fresh] RUNS DESIGN NU NV OUT.ext BINARY [BINARY ...]

With `--fresh` the output file is deleted (untimed) before each run, so the run writes a new
file rather than replacing one: replacing a large file makes the final rename free the old
file's blocks, which on this machine's ext4 (mounted with `discard`) takes about 23 ms for
100 MB. Older binaries may print fewer timing keys; missing ones are left blank.
"""
import json
import os
import statistics
import subprocess
import sys
import time

args = sys.argv[1:]
command = "surface"
fresh = False
while args and args[0] in ("--blend", "--fresh"):
    if args[0] == "--blend":
        command = "blend"
    else:
        fresh = True
    args = args[1:]
runs, design, nu, nv, out = int(args[0]), args[1], args[2], args[3], args[4]
binaries = args[5:]
keys = ["solve_ms", "tessellate_ms", "weld_ms", "file_ms", "commit_ms", "write_ms", "total_ms"]
results = {b: [] for b in binaries}
for _ in range(runs):
    for b in binaries:
        if fresh and os.path.exists(out):
            os.remove(out)
            os.sync()
        t = time.perf_counter()
        before = os.times()
        p = subprocess.run(
            [b, command, design, "-o", out, "--nu", nu, "--nv", nv, "--timings", "--quiet"],
            capture_output=True,
            text=True,
        )
        wall = (time.perf_counter() - t) * 1e3
        after = os.times()
        cpu_user = (after.children_user - before.children_user) * 1e3
        cpu_sys = (after.children_system - before.children_system) * 1e3
        if p.returncode != 0:
            sys.exit(f"{b}: {p.stderr}")
        line = [l for l in p.stderr.splitlines() if l.startswith("{")][-1]
        row = json.loads(line)
        row["wall_ms"] = wall
        row["cpu_user_ms"] = cpu_user
        row["cpu_sys_ms"] = cpu_sys
        row["bytes"] = os.path.getsize(out)
        results[b].append(row)
print(f"{runs} runs each, alternating; load average {os.getloadavg()[0]:.2f} at the end")
for b, rows in results.items():
    extra = ["wall_ms", "cpu_user_ms", "cpu_sys_ms"]
    med = {k: statistics.median(r[k] for r in rows) for k in keys + extra if k in rows[0]}
    size = rows[0]["bytes"]
    print(b, f"file {size / 1e6:.1f} MB")
    print("  " + "  ".join(f"{k} {med[k]:.1f}" for k in keys + extra if k in med))
    if "write_ms" in med:
        print(f"  write {size / med['write_ms'] / 1e6:.2f} GB/s of file", end="")
        if "file_ms" in med:
            print(f"; weld + file (to close) {size / (med['weld_ms'] + med['file_ms']) / 1e6:.2f} GB/s", end="")
        print()
