# SPDX-License-Identifier: LGPL-2.1-or-later
"""Shared helpers of the FreeCAD-headless tests: synthetic measurement files on real faces."""

import os

import numpy as np

from surfcomp.app.nominal import nominal_from_face
from surfcomp.core.surface import bspline

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLE_STEP = os.path.join(ROOT, "examples", "nominal.step")
EXAMPLE_CSV = os.path.join(ROOT, "examples", "measurements.csv")


def grid_on_face(nominal, n, m, margin=0.03):
    """Nominal points, outward normals and (u, v) of an n x m parameter grid on the face."""
    (u0, u1), (v0, v1) = nominal.surface.u_range, nominal.surface.v_range
    us = u0 + (u1 - u0) * np.linspace(margin, 1 - margin, n)
    vs = v0 + (v1 - v0) * np.linspace(margin, 1 - margin, m)
    U, V = np.meshgrid(us, vs, indexing="ij")
    P = bspline.evaluate(nominal.surface, U, V)
    N = bspline.normals(nominal.surface, U, V) * nominal.outward
    return P, N, U, V


def write_cmm_csv(path, P, N, d, header="x_nom,y_nom,z_nom,i,j,k,dev"):
    """Write a CMM report (nominal, direction cosines, deviation) in serpentine row order."""
    rows = [header]
    n, m = d.shape
    for j in range(m):
        order = range(n) if j % 2 == 0 else range(n - 1, -1, -1)
        for i in order:
            rows.append("%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.9f"
                        % (tuple(P[i, j]) + tuple(N[i, j]) + (d[i, j],)))
    with open(path, "w") as fh:
        fh.write("\n".join(rows) + "\n")


def realised_by_occt(face, P, N, reach=0.5):
    """Correction realised by ``face`` at points P along normals N, measured with OCCT.

    The segment P +- reach N is intersected with the face (distToShape gives the
    common point); returns t with X = P - t N.
    """
    import FreeCAD
    import Part

    out = []
    for p, n in zip(P.reshape(-1, 3), N.reshape(-1, 3)):
        a = FreeCAD.Vector(*(p - reach * n))
        b = FreeCAD.Vector(*(p + reach * n))
        dist, pairs, _ = face.distToShape(Part.LineSegment(a, b).toShape())
        assert dist < 1e-7, dist
        x = np.array(tuple(pairs[0][0]))
        out.append(float(np.dot(p - x, n)))
    return np.array(out)


def face_nominal(face, name="Face1"):
    return nominal_from_face(face, source="<test>", face_name=name)


def run_in_process(*args):
    """``python3 -m surfcomp ARGS`` run as ``surfcomp.cli.main`` in this process, as a
    ``CompletedProcess`` (exit code, standard output, standard error with the numeric
    warnings a real run prints there); the working directory, the signal handlers and the
    open FreeCAD documents are as they were afterwards (tests/fuzz/harness.py). For the
    runs whose results a test checks: it saves the interpreter's start and imports. The
    runs that check the program as a process (the exit code and message of refused input,
    signals) stay subprocesses."""
    import subprocess

    from tests.fuzz.harness import run_cli

    res = run_cli(args, ROOT)
    err = res.err + "".join("%s\n" % w for w in res.numeric_warnings)
    return subprocess.CompletedProcess(["surfcomp", *map(str, args)], res.rc, res.out, err)
