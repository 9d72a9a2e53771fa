#!/usr/bin/env python3
"""Runs Salvi's transfinite surfaces (bench/peers/salvi_fill.cc, built by build_salvi.sh) on
n-sided network cases (bench/peers/network_cases.py) and prints their figures beside
pdeshape's as Markdown tables.

usage: salvi_fill.py CASE.json... --bin SALVI_FILL [--repeat K] [--fences corner|raw]
                     [--ours OURS.jsonl] [--jsonl OUT.jsonl]

--bin      the salvi_fill program (OUTDIR/salvi_fill of build_salvi.sh)
--ours     the JSON lines printed by `cargo bench -p pdeshape --bench nsided_cases -- ...`
           (lines that are not JSON objects are skipped), shown in the first column
--jsonl    also writes every line salvi_fill printed to this file
--fences   passed to salvi_fill (default corner; see salvi_fill.cc)

Prints four tables (boundary, G1, distance to the truth, time), one row per case. Exit status
0, 1 when salvi_fill failed on a case, 2 on a usage error.
"""
import json
import subprocess
import sys

CONTINUOUS = ["sb", "cb", "gc", "cr", "mp", "mc", "el"]
DISCRETE = ["ha", "bh"]


def usage():
    print(__doc__.split("\n\n")[1], file=sys.stderr)
    sys.exit(2)


def fmt(x):
    if x is None:
        return "–"
    if x == 0:
        return "0"
    if x >= 0.1:
        return f"{x:.2f}"
    return f"{x:.1e}"


def ms(x):
    if x is None:
        return "–"
    x *= 1e3
    return f"{x:.3g}"


def main():
    args = sys.argv[1:]
    opts = {"--bin": None, "--repeat": "7", "--ours": None, "--jsonl": None, "--fences": "corner"}
    cases = []
    i = 0
    while i < len(args):
        if args[i] in opts and i + 1 < len(args):
            opts[args[i]] = args[i + 1]
            i += 2
        elif args[i].startswith("--"):
            usage()
        else:
            cases.append(args[i])
            i += 1
    if not cases or not opts["--bin"]:
        usage()

    ours = {}
    if opts["--ours"]:
        with open(opts["--ours"]) as f:
            for line in f:
                line = line.strip()
                if line.startswith("{"):
                    rec = json.loads(line)
                    ours[rec["case"]] = rec

    rows = {}  # case -> type -> record
    order = []
    out = open(opts["--jsonl"], "w") if opts["--jsonl"] else None
    status = 0
    for case in cases:
        cmd = [opts["--bin"], case, "--repeat", opts["--repeat"], "--fences", opts["--fences"]]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            print(f"salvi_fill.py: {case}: {run.stderr.strip()}", file=sys.stderr)
            status = 1
            continue
        for line in run.stdout.splitlines():
            rec = json.loads(line)
            if out:
                out.write(line + "\n")
            if rec["case"] not in rows:
                rows[rec["case"]] = {}
                order.append(rec["case"])
            rows[rec["case"]][rec["type"]] = rec
    if out:
        out.close()

    def table(title, head, cell):
        print(f"\n{title}\n")
        print("| case | " + " | ".join(head) + " |")
        print("|---" * (len(head) + 1) + "|")
        for name in order:
            print(f"| {name} | " + " | ".join(cell(name, h) for h in head) + " |")

    def rec(name, t):
        r = rows[name].get(t)
        return r if r and "error" not in r else None

    def field(name, t, key):
        if t == "ours":
            return ours.get(name, {}).get(key)
        r = rec(name, t)
        return None if r is None else r.get(key)

    key_ours = {"boundary": "boundary", "g1": "g1", "truth_max": "truth_max"}
    table("Boundary (largest distance from the case's points to the surface)",
          ["ours"] + CONTINUOUS + DISCRETE,
          lambda n, t: fmt(field(n, t, key_ours["boundary"])))
    table("G1 (largest angle, rad, to the case's normals, corners excluded)",
          ["ours"] + CONTINUOUS,
          lambda n, t: fmt(field(n, t, "g1")))
    table("Distance to the truth (largest, over the tessellation / grid)",
          ["ours"] + CONTINUOUS + DISCRETE,
          lambda n, t: fmt(field(n, t, "truth_max")))

    def time_cell(n, t):
        if t == "ours":
            o = ours.get(n)
            if not o:
                return "–"
            return f"{ms(o['again_median_s'])} ({ms(o['first_median_s'])})"
        r = rec(n, t)
        if r is None:
            return "–"
        if t in DISCRETE:
            return ms(r["build_median_s"])
        return f"{ms(r['build_median_s'])} + {ms(r['mesh_median_s'])}"

    table("Time, ms (ours: re-solve (first solve); transfinite: build + evaluation of the "
          "resolution-40 mesh; discrete: build with the mesh solve)",
          ["ours"] + CONTINUOUS + DISCRETE, time_cell)
    errors = [(n, t, r["error"]) for n in order for t, r in rows[n].items() if "error" in r]
    for n, t, e in errors:
        print(f"\n{n} {t}: {e}")
    sys.exit(status)


if __name__ == "__main__":
    main()
