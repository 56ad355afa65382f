# SPDX-License-Identifier: LGPL-2.1-or-later
"""How long the window freezes while Restore and Replace recompute a fine 3D Surface job.

    xvfb-run -a -s "-screen 0 1600x1200x24" /usr/bin/python3 bench/bench_responsive.py \
        [--step-over 10] [--sample-interval 0.3]

Runs inside the real FreeCAD GUI (tests/gui/harness.py) the session of
tests/gui/test_responsive.py on the shop document (tests/data/documents/shop-0.20.FCStd) with
its 3D Surface operation made fine (step over in % of the 6 mm tool, sample interval in mm):
Restore nominal, then Replace in document. A label in the status bar asks for a repaint every
40 ms; the longest time between two of its paint events during the command is the freeze.
Twice: with the operations recomputed in the GUI process (each object once, as before the
child process) and with the operations recomputed in a child process (what the commands do).
Prints seconds.
"""

import argparse
import os
import pathlib
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from tests.gui.harness import run_session  # noqa: E402


def run(in_process, args):
    env = {"SURFCOMP_STEP_OVER": str(args.step_over),
           "SURFCOMP_SAMPLE_INTERVAL": str(args.sample_interval),
           "SURFCOMP_IN_PROCESS": "1" if in_process else "0", "SURFCOMP_SKIP_ESC": "1"}
    with tempfile.TemporaryDirectory() as tmp:
        res = run_session("responsive", pathlib.Path(tmp), timeout=3600, env=env)
    if res["errors"]:
        print("\n".join(res["errors"]))
        raise SystemExit(1)
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--step-over", type=float, default=10.0)
    ap.add_argument("--sample-interval", type=float, default=0.3)
    ap.add_argument("--child-only", action="store_true",
                    help="only the recompute in a child process")
    ap.add_argument("--details", action="store_true",
                    help="also the gaps over 0.3 s (start in the command, length) and the "
                         "steps' times")
    args = ap.parse_args()
    for in_process in ((False,) if args.child_only else (True, False)):
        res = run(in_process, args)
        how = "in the GUI process" if in_process else "in a child process"
        print("FreeCAD %s, operations recomputed %s: 3D Surface with %d commands"
              % (res["freecad"], how, res["fine_commands"]))
        for step in ("restore", "replace"):
            r = res[step]
            print("  %-8s %6.1f s, longest gap between repaints %6.2f s, operation computed "
                  "%d x here, %s in the child" % (step, r["seconds"], r["gap"],
                                                  r["gui_executions"],
                                                  r["child_executions"] or "-"))
            if args.details:
                print("    gaps over 0.3 s: %s" % r["gaps"])
                print("    steps: %s" % r["phases"])
                print("    in the child: %s" % r["child_seconds"])
    print("load average %.1f" % os.getloadavg()[0])


if __name__ == "__main__":
    main()
