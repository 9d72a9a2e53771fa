"""Sweep throughput: `pdeshape.sweep.sweep` of the cup over an n × n grid of (bellyDx, rimDy) on
a LocalCluster of 2 single-threaded workers, against a plain serial loop (with_params +
analysis) in this process. Prints variants per second and the ratio.

    python bench/peers/py_sweep.py [n] [worker_rayon_threads]

With `worker_rayon_threads` the workers run with RAYON_NUM_THREADS set to it (the library's
thread pool per worker process; by default each process has one thread per core).
"""

import sys
import time

import numpy as np
from dask.distributed import Client, LocalCluster

import pdeshape
from pdeshape.sweep import grid, sweep

def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    worker_env = {"RAYON_NUM_THREADS": sys.argv[2]} if len(sys.argv) > 2 else {}
    cup = pdeshape.Design.load("examples/cup.toml")
    table = grid(bellyDx=np.linspace(0.8, 1.2, n), rimDy=np.linspace(0.9, 1.1, n))
    rows = len(table["bellyDx"])

    t = time.perf_counter()
    serial = [
        cup.with_params({"bellyDx": a, "rimDy": b}).analysis()["total"]["volume"]
        for a, b in zip(table["bellyDx"], table["rimDy"])
    ]
    ts = time.perf_counter() - t

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None, env=worker_env)
    with cluster, Client(cluster) as c:
        assert c.run(lambda: __import__("os").environ.get("RAYON_NUM_THREADS")) == {
            w: worker_env.get("RAYON_NUM_THREADS") for w in c.scheduler_info()["workers"]
        }
        t = time.perf_counter()
        df = sweep(cup, table, measures=["volume"], client=c)
        tc = time.perf_counter() - t
    assert df["volume"].tolist() == serial
    print(f"{rows} cup variants, workers' RAYON_NUM_THREADS = {worker_env.get('RAYON_NUM_THREADS', 'unset')}")
    print(f"serial loop        {ts:.2f} s  {rows / ts:.1f} variants/s")
    print(f"LocalCluster(2x1)  {tc:.2f} s  {rows / tc:.1f} variants/s")
    print(f"speed-up {ts / tc:.2f}")


if __name__ == "__main__":  # the workers start processes that import this file
    main()
