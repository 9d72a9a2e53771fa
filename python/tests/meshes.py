"""Closed triangle meshes of ellipsoids for the fitting tests (the CLI's tests use the same
latitude-longitude construction)."""

from __future__ import annotations

import math


def ellipsoid_obj(rings: int, around: int, a: float = 1.0, c: float = 1.5) -> str:
    """The ellipsoid x² + y² over a², z² over c², as an OBJ of `rings` latitude bands (alternate
    rings turned by half a step) with a vertex at each pole; outward-facing triangles."""
    out = ["# ellipsoid", f"v 0 0 {-c!r}"]
    for i in range(1, rings):
        t = math.pi * i / rings
        for j in range(around):
            phi = 2 * math.pi * (j + 0.5 * (i % 2)) / around
            out.append(f"v {a * math.sin(t) * math.cos(phi)!r} {a * math.sin(t) * math.sin(phi)!r} {-c * math.cos(t)!r}")
    out.append(f"v 0 0 {c!r}")
    top = 1 + (rings - 1) * around + 1

    def at(i: int, j: int) -> int:
        return 2 + (i - 1) * around + j % around

    for j in range(around):
        out.append(f"f 1 {at(1, j + 1)} {at(1, j)}")
        out.append(f"f {top} {at(rings - 1, j)} {at(rings - 1, j + 1)}")
    for i in range(1, rings - 1):
        for j in range(around):
            out.append(f"f {at(i, j)} {at(i, j + 1)} {at(i + 1, j + 1)}")
            out.append(f"f {at(i, j)} {at(i + 1, j + 1)} {at(i + 1, j)}")
    return "\n".join(out) + "\n"


def torus_obj(around: int, tube: int, big: float = 1.0, small: float = 0.35) -> str:
    """The torus of radii `big` and `small` about z, as an OBJ of `around` × `tube` quads split
    into outward-facing triangles (a closed mesh of genus 1: neither a tube nor a sheet)."""
    out = ["# torus"]
    for i in range(around):
        phi = 2 * math.pi * i / around
        for j in range(tube):
            theta = 2 * math.pi * j / tube
            r = big + small * math.cos(theta)
            out.append(f"v {r * math.cos(phi)!r} {r * math.sin(phi)!r} {small * math.sin(theta)!r}")

    def at(i: int, j: int) -> int:
        return 1 + (i % around) * tube + j % tube

    for i in range(around):
        for j in range(tube):
            out.append(f"f {at(i, j)} {at(i + 1, j)} {at(i + 1, j + 1)}")
            out.append(f"f {at(i, j)} {at(i + 1, j + 1)} {at(i, j + 1)}")
    return "\n".join(out) + "\n"
