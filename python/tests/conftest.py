"""Shared fixtures: the repository's examples and the CLI binary the results are compared with."""

from __future__ import annotations

import os
import pathlib
import subprocess

import pytest
from dask.distributed import Client, LocalCluster

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def cli_path() -> pathlib.Path:
    """The `pdeshape` binary: $PDESHAPE_CLI, else the release build under $CARGO_TARGET_DIR or
    target/. Missing is a failure, not a skip (.ci/python.sh builds it)."""
    if "PDESHAPE_CLI" in os.environ:
        p = pathlib.Path(os.environ["PDESHAPE_CLI"])
    else:
        target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
        p = target / "release" / "pdeshape"
    assert p.is_file(), f"the pdeshape CLI binary is missing at {p} (cargo build --release -p pdeshape-cli)"
    return p


@pytest.fixture(scope="session")
def cli():
    exe = cli_path()

    def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
        r = subprocess.run([str(exe), *args], capture_output=True, text=True)
        if check:
            assert r.returncode == 0, r.stderr
        return r

    return run


@pytest.fixture
def cup_path() -> pathlib.Path:
    return EXAMPLES / "cup.toml"


@pytest.fixture(scope="module")
def client():
    """A dask.distributed LocalCluster of 2 single-threaded worker processes, one per test module."""
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    with Client(cluster) as c:
        yield c
    cluster.close()
