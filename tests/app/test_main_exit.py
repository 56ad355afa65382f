# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp`` as a process of its own (its start-up objects frozen for the
collector) and run by another program through ``runpy``: what it printed (block-buffered
into a file) and its exit code are kept, and the other program goes on."""

import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_printed_text_and_exit_code_survive(tmp_path):
    """An error (exit 2) and the example's compensation (its summary, 1.3 kB), both into
    files, where Python buffers what is printed until the exit."""
    out, err = tmp_path / "out.txt", tmp_path / "err.txt"
    face = tmp_path / "corrected.step"
    cases = ((["compensate", "examples/nominal.step", str(tmp_path / "missing.csv"), "-o",
               str(tmp_path / "x.step")], 2),
             (["compensate", "examples/nominal.step", "examples/measurements.csv", "-o",
               str(face)], 0))
    for argv, code in cases:
        with open(out, "w") as fo, open(err, "w") as fe:
            rc = subprocess.run([sys.executable, "-m", "surfcomp"] + argv, cwd=ROOT,
                                stdout=fo, stderr=fe).returncode
        assert rc == code
        if code:
            assert "missing.csv" in err.read_text() and "No such file" in err.read_text()
            assert not (tmp_path / "x.step").exists()
        else:
            lines = out.read_text().splitlines()
            assert lines[0].startswith("Nominal:") and lines[-1] == "wrote %s" % face
            assert len(lines) > 20 and face.read_text().rstrip().endswith("END-ISO-10303-21;")


def test_a_program_that_runs_the_module_goes_on_after_it(tmp_path):
    """Run through ``runpy`` from another program's process, the command returns to it
    (SystemExit with the command's code), which then goes on."""
    code = ("import runpy, sys\nsys.argv = ['surfcomp'] + sys.argv[1:]\ntry:\n"
            "    runpy.run_module('surfcomp', run_name='__main__', alter_sys=True)\n"
            "except SystemExit as exc:\n    print('went on after', exc.code)\n")
    res = subprocess.run([sys.executable, "-c", code, "compensate", "examples/nominal.step",
                          str(tmp_path / "missing.csv"), "-o", str(tmp_path / "x.step")],
                         cwd=ROOT, capture_output=True, text=True)
    assert res.returncode == 0 and res.stdout.strip() == "went on after 2", res.stderr
