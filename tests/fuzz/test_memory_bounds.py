# SPDX-License-Identifier: LGPL-2.1-or-later
"""``--max-memory`` on ``inspect``, ``compensate`` (files and the shop document) and
``gcode`` (issue 25, item 7): a run whose estimated peak memory is above the limit is
refused before the work, naming the estimate and the limit, nothing written; under the
limit it runs. (``simulate``'s cases are
in test_simulate_cases.py; the estimates are checked in tests/pure/test_budget.py and
against measured peaks by bench/bench_memory.py.)"""

import pytest

from . import inputs as I
from .harness import EXAMPLE_STEP, Case, run_case

JOB = I.setup(I.copy("n.step", EXAMPLE_STEP), I.put("m.csv", I.csv))
GCODE = I.setup(I.put("in.ngc", I.SMALL_PROGRAM), I.put("e.csv", I.AXIS_CSV))

CASES = [
    Case("inspect-64M", ("inspect", "n.step", "m.csv", "--max-memory", "64M", "--report",
                         "r.json", "--quiet"), JOB,
         says=("inspect of 225 points needs about 0.3 GB of memory, more than --max-memory "
               "(64 MB)",)),
    Case("compensate-0.1G", ("compensate", "n.step", "m.csv", "-o", "c.step", "--quiet",
                             "--max-memory=0.1g"), JOB,
         says=("compensate of 225 points needs about 0.3 GB", "--max-memory (102 MB)")),
    Case("gcode-65M", ("gcode", "in.ngc", "--axis-errors", "e.csv", "-o", "out.ngc",
                       "--max-memory", "65M"), GCODE,
         says=("gcode on 8 lines needs about 0.3 GB of memory", "split the program")),
    Case("compensate-4G", ("compensate", "n.step", "m.csv", "-o", "c.step", "--quiet",
                           "--max-memory", "4G"), JOB, rc=0, writes=("c.step",)),
    # the document route estimates the compensation from the points read, before it adds
    # anything to the document (FreeCAD's CAM recompute is not estimated)
    Case("document-route-64M", ("compensate", "d.FCStd", "m.csv", "--object", "Nominal",
                                "--replace", "--save", "out.FCStd", "--max-memory", "64M"),
         I.setup(I.put("d.FCStd", I.document_bytes), I.put("m.csv", I.csv)),
         says=("compensate of 225 points needs about 0.3 GB of memory, more than "
               "--max-memory (64 MB)",)),
    Case("document-route-8G", ("compensate", "d.FCStd", "m.csv", "--object", "Nominal",
                               "--save", "out.FCStd", "--max-memory", "8G", "--quiet"),
         I.setup(I.put("d.FCStd", I.document_bytes), I.put("m.csv", I.csv)),
         rc=0, writes=("out.FCStd",)),
    Case("inspect-size-garbage", ("inspect", "n.step", "m.csv", "--max-memory", "4 GB RAM"),
         JOB, usage=True, says=("argument --max-memory: expected a size",)),
]


@pytest.mark.parametrize("case", CASES, ids=str)
def test_case(case, tmp_path, cad_cache):
    run_case(case, tmp_path)
