"""No memory leak over 10 000 solves (resident set size measured)."""

from __future__ import annotations

import gc

import psutil

from pdeshape import Design


def test_no_leak_over_10000_solves(cup_path):
    text = cup_path.read_text()
    proc = psutil.Process()

    def batch(n):
        for i in range(n):
            d = Design.from_toml(text).with_params({"bellyDx": 1.0 + (i % 100) * 1e-3})
            d.solve()
            d.tessellate(8, 16)
        gc.collect()

    batch(500)  # warm up: allocator pools, caches, the interpreter's own growth
    before = proc.memory_info().rss
    batch(10_000)
    after = proc.memory_info().rss
    # One solved cup with its 8 × 16 samples holds ~50 kB; a leak of any of them per solve would
    # grow the RSS by ≥ 500 MB over 10 000 solves. Allocator noise stays within a few MB.
    assert after - before < 16 * 2**20, f"RSS grew by {(after - before) / 2**20:.1f} MiB"
