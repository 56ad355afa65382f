# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate --program`` refuses a program whose moves near the face would be planned at
more pieces than the limit (here 300 passes of 41 mm at ``--segment-length 0.001``, about
12 million pieces): exit 2, the message names the figure, the limit and the option, and
nothing is written."""

import os
import subprocess
import sys

from surfcomp.core.limits import MAX_SEGMENTS
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT
from tests.pure.test_program_limit import passes


def test_too_many_pieces_exit_2_and_write_nothing(tmp_path):
    text, cuts = passes(300)
    prog = tmp_path / "long.ngc"
    prog.write_text(text)
    out = tmp_path / "out.ngc"
    run = subprocess.run([sys.executable, "-m", "surfcomp", "compensate", EXAMPLE_STEP,
                          EXAMPLE_CSV, "--program", str(prog), "--tool", "ball:3",
                          "--segment-length", "0.001", "-o", str(out), "--quiet"],
                         capture_output=True, text=True, cwd=ROOT, timeout=600,
                         env=dict(os.environ, PYTHONPATH=ROOT))
    assert run.returncode == 2, run.stderr
    err = run.stderr
    assert "long.ngc:%d: --segment-length 0.001 mm" % cuts[244][0] in err, err
    assert "more than %d pieces" % MAX_SEGMENTS in err
    assert "expected a --segment-length of at least 0.00124 mm" in err
    assert sorted(os.listdir(tmp_path)) == ["long.ngc"]
    assert prog.read_text() == text
