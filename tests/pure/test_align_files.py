# SPDX-License-Identifier: LGPL-2.1-or-later
"""The alignment's input files and job keys (issue 28): transforms, 3-2-1 sets, bad input."""

import json

import numpy as np
import pytest

from surfcomp.core.measurement.align import check_rigid
from surfcomp.core.measurement.align_report import AlignOptions
from surfcomp.errors import InputError
from surfcomp.io.align_files import read_rps, read_transform
from surfcomp.io.jobfile import check_values


def test_transform_text_json_and_work_offset(tmp_path):
    M = np.eye(4)
    M[:3, 3] = [1.5, -2.0, 3.25]
    (tmp_path / "m.txt").write_text("# measured -> nominal\n" + "\n".join(
        ", ".join("%.17g" % x for x in row) for row in M[:3]) + "\n")
    np.testing.assert_array_equal(read_transform(str(tmp_path / "m.txt")), M)
    (tmp_path / "m.json").write_text(json.dumps({"matrix": M.tolist()}))
    np.testing.assert_array_equal(read_transform(str(tmp_path / "m.json")), M)
    (tmp_path / "w.json").write_text(json.dumps({"translation": [10, 0, 0],
                                                 "rotation_z_deg": 90}))
    W = read_transform(str(tmp_path / "w.json"))
    np.testing.assert_allclose(W[:3, :3] @ [1.0, 0.0, 0.0] + W[:3, 3], [10.0, 1.0, 0.0],
                               atol=1e-15)
    assert check_rigid(W) is not None


def test_transform_file_errors(tmp_path):
    (tmp_path / "bad.txt").write_text("1 0 0 0\n0 1 0 x\n")
    with pytest.raises(InputError, match=r"bad.txt:2: expected numbers, got '0 1 0 x'"):
        read_transform(str(tmp_path / "bad.txt"))
    (tmp_path / "short.txt").write_text("1 0 0\n")
    with pytest.raises(InputError, match=r"short.txt:1: a matrix row has 3 numbers"):
        read_transform(str(tmp_path / "short.txt"))
    (tmp_path / "j.json").write_text('{"matrix": [[1, 0]]}')
    with pytest.raises(InputError, match="4 rows of 4 numbers"):
        read_transform(str(tmp_path / "j.json"))
    (tmp_path / "s.txt").write_text("2 0 0 0\n0 2 0 0\n0 0 2 0\n")
    with pytest.raises(InputError, match="not rigid"):
        AlignOptions(transform=read_transform(str(tmp_path / "s.txt")),
                     transform_source=str(tmp_path / "s.txt")).validate()


def test_rps_inline_and_json(tmp_path):
    groups, source = read_rps("P1, P2,P3;P4,P5;P6")
    assert groups == {"primary": ["P1", "P2", "P3"], "secondary": ["P4", "P5"],
                      "tertiary": ["P6"]} and source == "--rps"
    (tmp_path / "r.json").write_text(json.dumps({"primary": [1, 2, 3], "secondary": [4, 5],
                                                 "tertiary": [6]}))
    assert read_rps(str(tmp_path / "r.json"))[0]["secondary"] == [4, 5]
    with pytest.raises(InputError, match="three groups of point ids"):
        read_rps("1,2,3;4,5")


def test_align_options_and_job_keys():
    with pytest.raises(InputError, match="^align 'best': expected one of none, bestfit, rps"):
        AlignOptions("best").validate()
    with pytest.raises(InputError, match="^align 'rps' needs rps"):
        AlignOptions("rps").validate()
    with pytest.raises(InputError, match="^rps is used by align 'rps' only"):
        AlignOptions("bestfit", rps={"primary": []}).validate()
    with pytest.raises(InputError, match="job key 'align' is \"maybe\""):
        check_values({"align": "maybe"})
    with pytest.raises(InputError, match="job key 'align_dof' is 3"):
        check_values({"align_dof": 3})
    assert check_values({"align": "bestfit", "align_faces": "Face1,Face2", "align_dof": "xyz",
                         "transform": "t.json", "rps": None})
