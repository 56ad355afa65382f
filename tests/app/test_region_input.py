# SPDX-License-Identifier: LGPL-2.1-or-later
"""Region input the route must not take silently (issue 30): points beyond a face's own
border."""

import numpy as np
import pytest

from tests.app import region_parts as rp


@pytest.fixture(scope="module")
def part(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("region_input")
    solid, tops = rp.g1_top_solid()
    step = str(tmp / "g1.step")
    solid.exportStep(step)
    pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 1500, rp.ridge_field,
                                    seed=4)
    csv = str(tmp / "g1.csv")
    rp.write_csv(csv, pts, nrm, dev)
    return tmp, step, csv, pts, nrm, dev


def test_points_beyond_the_border_of_a_face_are_on_no_face(part):
    """40 readings of 50 um 0.3 mm beside the top's edge y = 0 (in the air, beyond the
    faces' own border: their nearest point is the edge, not a foot on the face) were
    counted on Face1 and Face2 and bent the correction there."""
    tmp, step, _csv, pts, nrm, dev = part
    xs = np.linspace(1.0, 19.0, 40)
    beside = np.array([[x, -0.3, rp._h(x, -0.3)] for x in xs])
    csv = str(tmp / "beside.csv")
    rp.write_csv(csv, np.concatenate([pts, beside]),
                 np.concatenate([nrm, np.tile([0.0, 0.0, 1.0], (40, 1))]),
                 np.concatenate([dev, np.full(40, 0.05)]))
    r = rp.run(step, csv, "--faces", "Face1,Face2", "-o", str(tmp / "beside.step"))
    assert r.returncode == 0, r.stderr
    assert "points per face: Face1 1500, Face2 1500; on no face: 40" in r.stdout, r.stdout
