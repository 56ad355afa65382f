# SPDX-License-Identifier: LGPL-2.1-or-later
"""The JSON report is written in parts (issue 25, item 7: 3 million points ran out of memory
at 6.9 GB in the JSON encoder): the text is what ``json`` reads back to the same values,
and no single write is larger than a part of the arrays, whatever the number of points."""

import io
import json

import numpy as np
import pytest

from surfcomp.io import report as report_io


class _Recorder(io.StringIO):
    def __init__(self):
        super().__init__()
        self.largest = 0

    def write(self, text):
        self.largest = max(self.largest, len(text))
        return super().write(text)


def _report(n, rng):
    return {"schema": report_io.SCHEMA, "inputs": {"nominal": {"path": "n\udcff.step"}},
            "points": {"line": np.arange(2, n + 2), "row": None,
                       "u": rng.uniform(0, 1, n), "nominal": rng.normal(size=(n, 3)),
                       "deviation": np.r_[rng.normal(size=n - 1), np.nan]},
            "warnings": ["w"]}


def test_points_written_in_parts_read_back_equal():
    rng = np.random.default_rng(7)
    n = 3 * report_io.CHUNK + 17
    rep = _report(n, rng)
    fh = _Recorder()
    report_io.write(rep, fh)
    text = fh.getvalue()
    back = json.loads(text)
    assert back["schema"] == report_io.SCHEMA and back["warnings"] == ["w"]
    assert back["inputs"]["nominal"]["path"] == "n\udcff.step"
    assert back["points"]["row"] is None
    assert back["points"]["line"] == list(range(2, n + 2))
    np.testing.assert_array_equal(back["points"]["u"], rep["points"]["u"])
    np.testing.assert_array_equal(back["points"]["nominal"], rep["points"]["nominal"])
    np.testing.assert_array_equal(back["points"]["deviation"][:-1],
                                  rep["points"]["deviation"][:-1])
    # JSON has no NaN (strict readers refuse Python's NaN): a value that is not a number
    # is null, and the text reads back with a strict reader
    assert back["points"]["deviation"][-1] is None
    json.loads(text, parse_constant=lambda c: pytest.fail("%s in the JSON text" % c))
    # one part of the (n, 3) array is the largest piece of text ever held
    part = len(json.dumps(rep["points"]["nominal"][:report_io.CHUNK].tolist()))
    assert fh.largest <= 1.01 * part      # parts differ by a few digits
    assert len(text) > 4 * part
    assert report_io.dumps(rep) == text


def test_report_without_points_and_empty_arrays():
    rep = {"schema": report_io.SCHEMA, "points": None}
    assert json.loads(report_io.dumps(rep)) == rep
    empty = {"points": {"u": np.zeros(0), "nominal": np.zeros((0, 3))}}
    assert json.loads(report_io.dumps(empty)) == {"points": {"u": [], "nominal": []}}


def test_values_that_are_not_numbers_are_null_in_the_dict_too():
    rep = {"alignment": {"rms_before_um": float("nan"), "faces": [{"rms": float("inf")}]},
           "points": {"deviation": np.array([[1.0, np.nan], [np.inf, 2.0]])}}
    text = report_io.dumps(rep)
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"alignment": {"rms_before_um": None, "faces": [{"rms": None}]},
                                "points": {"deviation": [[1.0, None], [None, 2.0]]}}
