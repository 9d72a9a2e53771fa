#!/usr/bin/env python3
"""The server's share of a drag in the designer: starts `pdeshape serve DESIGN`, then posts N
`move_control_point` edits of control point INDEX of CURVE (one drag: one group), moving it
round a circle of radius 0.05 in x and y, and prints the server's own time per frame (the
frame's `server_ms`, and its phases: the edit with the re-solve, the meshes, the colours, the
scene's curves), the wall time per request and the frame size.

usage: serve_drag.py PDESHAPE DESIGN CURVE N [INDEX] [GRID]

CURVE is made a B-spline first when it is not one ("Make B-spline"). INDEX defaults to 3;
GRID is the view's query, default `nu=32&nv=64` (the half grid the page asks for while
dragging at the default 64 × 128). Prints the five slowest frames (the drag's second frame
makes the affine model of the surfaces the point moves) and the medians and 95th percentiles.
Exit status 0, or 2 on a usage error.
"""
import json
import math
import re
import struct
import subprocess
import sys
import time
import urllib.error
import urllib.request


def main() -> int:
    if len(sys.argv) < 5:
        usage = next(x for x in __doc__.splitlines() if x.startswith("usage:"))
        print(usage, file=sys.stderr)
        return 2
    exe, design, curve, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    index = int(sys.argv[5]) if len(sys.argv) > 5 else 3
    grid = sys.argv[6] if len(sys.argv) > 6 else "nu=32&nv=64"
    proc = subprocess.Popen([exe, "serve", design, "--port", "0"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    try:
        url = token = None
        while url is None:
            line = proc.stdout.readline()
            if not line:
                print("serve_drag.py: the server did not start", file=sys.stderr)
                return 1
            m = re.search(r"(http://\S+/\?token=([0-9a-f]+))", line)
            if m:
                url, token = m.group(1), m.group(2)
        base = url.split("/?")[0]
        headers = {"x-pdeshape-token": token, "content-type": "application/json", "origin": base}

        def post(path, body):
            req = urllib.request.Request(base + path, data=json.dumps(body).encode(),
                                         method="POST", headers=headers)
            with urllib.request.urlopen(req) as r:
                return r.read()

        def scene_of(frame):
            k = struct.unpack("<I", frame[4:8])[0]
            return json.loads(frame[8:8 + k])

        try:
            frame = post("/api/convert?" + grid, {"name": curve})
        except urllib.error.HTTPError:
            req = urllib.request.Request(base + "/api/frame?" + grid, headers=headers)
            frame = urllib.request.urlopen(req).read()
        c = [k for k in scene_of(frame)["curves"] if k["name"] == curve][0]
        p = c["control"][index]
        server, wall, split = [], [], {}
        for i in range(n):
            a = 2 * math.pi * i / 50
            q = [p[0] + 0.05 * math.cos(a), p[1] + 0.05 * math.sin(a), p[2]]
            t0 = time.perf_counter()
            frame = post("/api/edit?" + grid, {"edit": {"edit": "move_control_point", "name": curve,
                                                       "index": index, "point": q},
                                              "group": 1, "world": True})
            wall.append((time.perf_counter() - t0) * 1000)
            scene = scene_of(frame)
            server.append(scene["server_ms"])
            for k, v in scene.get("server_split", {}).items():
                split.setdefault(k, []).append(v)
    finally:
        proc.send_signal(2)
        proc.wait()

    def q(xs, f):
        return sorted(xs)[int(f * (len(xs) - 1))]

    print("slowest frames (ms):", " ".join(f"{x:.1f}" for x in sorted(server)[-5:]))
    print(f"server p50 {q(server, .5):.2f} p95 {q(server, .95):.2f} ms; "
          f"wall p50 {q(wall, .5):.2f} p95 {q(wall, .95):.2f} ms; bytes {len(frame)}")
    if split:
        print("server phases p50 / p95 (ms): " + ", ".join(
            f"{k} {q(v, .5):.2f} / {q(v, .95):.2f}" for k, v in split.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
