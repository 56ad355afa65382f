# SPDX-License-Identifier: LGPL-2.1-or-later
"""``--faces auto`` leaves out faces with fewer than 10 points (issue 30): their points lie
on a face, so the run reports them by the face's name, apart from the points on no face."""

import json

import numpy as np

from tests.app import region_parts as rp


def test_points_of_a_face_left_out_are_not_on_no_face(tmp_path):
    solid, tops = rp.g1_top_solid()
    step = str(tmp_path / "g1.step")
    solid.exportStep(step)
    pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 3000, rp.ridge_field,
                                    seed=3)
    # 6 points on the wall y = 0 (2 to 3.5 mm below the top: farther than max_offset
    # 1 mm from it), 4 points 5 mm above the top (on no face)
    (wall,) = [k for k, f in enumerate(solid.Faces)
               if all(abs(v.Point.y) < 1e-9 for v in f.Vertexes)]
    on_wall = np.array([[x, 0.0, z] for x, z in zip(np.linspace(3, 17, 6),
                                                     np.linspace(1.0, 2.5, 6))])
    above = np.array([[x, 5.0, 11.0] for x in (4.0, 8.0, 12.0, 16.0)])
    extra = np.concatenate([on_wall, above])
    normals = np.concatenate([np.tile([0.0, -1.0, 0.0], (6, 1)),
                              np.tile([0.0, 0.0, 1.0], (4, 1))])
    csv = str(tmp_path / "points.csv")
    rp.write_csv(csv, np.concatenate([pts, extra]), np.concatenate([nrm, normals]),
                 np.concatenate([dev, np.zeros(len(extra))]))
    rep = str(tmp_path / "out.json")
    r = rp.run(step, csv, "--faces", "auto", "-o", str(tmp_path / "out.step"), "--report", rep)
    assert r.returncode == 0, r.stderr
    name = "Face%d" % (wall + 1)
    top = ", ".join("Face%d 3000" % (k + 1) for k in tops)
    assert ("points per face: %s; on no face: 4; on faces left out (fewer than 10 points): "
            "%s 6" % (top, name)) in r.stdout, r.stdout
    data = json.load(open(rep))
    assert data["points_on_no_face"] == 4
    assert data["points_on_dropped_faces"] == {name: 6}
    assert [f["face"] for f in data["faces"]] == ["Face%d" % (k + 1) for k in tops]
