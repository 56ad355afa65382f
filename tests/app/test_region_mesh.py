# SPDX-License-Identifier: LGPL-2.1-or-later
"""A region's correction does not depend on a mesh drawn on its shape: the GUI draws the
nominal (a triangulation on the shape), and OCCT's ``BoundBox`` of a meshed shape bounds
the mesh, not the geometry; the field radius, a share of the box's diagonal, differed
between the GUI and the command line for the same files."""

import pytest

from surfcomp.app.region_route import compute_region
from surfcomp.io.readers import read_any
from tests.app import region_parts as rp


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("region_mesh")
    return rp.g1_step(tmp, 800, seed=6)


def _run(shape, csv, step):
    ms = read_any(csv, "mm", "auto", None)
    _out, rep = compute_region(shape, ms, "Face1,Face2", (step, csv), log=lambda _t: None)
    return rep


def test_the_region_is_the_same_with_the_shape_meshed(block):
    import Part

    step, csv, _solid, *_ = block
    plain = _run(Part.read(step), csv, step)
    drawn = Part.read(step)
    before = drawn.BoundBox.DiagonalLength
    drawn.tessellate(0.05)          # what the GUI's display does to the shape
    assert abs(drawn.BoundBox.DiagonalLength - before) > 1e-3      # OCCT bounds the mesh
    meshed = _run(drawn, csv, step)
    assert meshed["field_radius_mm"] == plain["field_radius_mm"]
    for a, b in zip(plain["faces"], meshed["faces"]):
        assert a["max_realised_minus_intended_um"] == b["max_realised_minus_intended_um"]
        assert a["poles"] == b["poles"]
