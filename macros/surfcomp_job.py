# SPDX-License-Identifier: LGPL-2.1-or-later
"""Run a surfcomp job file inside ``freecadcmd`` (the FreeCAD route of the batch CLI).

    SURFCOMP_JOB=job.json freecadcmd macros/surfcomp_job.py

The job file is a JSON object with the same names as the CLI (README, "freecadcmd"):
``{"command": "compensate", "nominal": "nominal.step", "measurements": "meas.csv",
"output": "out/corrected.step", "report": "out/report.json", "method": "filtered",
"mask_size": 5}``; relative paths are relative to the job file. Exit code as the CLI:
0 ok, 2 bad input (nothing written), 1 internal error.
"""

import os
import sys
import traceback


def _main():
    here = os.path.dirname(os.path.abspath(globals().get("__file__") or sys.argv[0]))
    root = os.path.dirname(here)
    if root not in sys.path:
        sys.path.insert(0, root)
    from surfcomp.app.file_route import load_job_file, run_job
    from surfcomp.cli.common import ProgressLine, print_summary
    from surfcomp.errors import SurfcompError

    path = os.environ.get("SURFCOMP_JOB")
    if not path:
        print("surfcomp: error: set SURFCOMP_JOB to the job file (JSON)", file=sys.stderr)
        return 2
    try:
        job = load_job_file(path)
        comp, rep = run_job(job, progress=ProgressLine())
        print_summary(comp, rep)
        for key in ("output", "points", "curves", "report"):
            if getattr(job, key):
                print("wrote %s" % getattr(job, key))
        return 0
    except SurfcompError as exc:
        print("surfcomp: error: %s" % exc, file=sys.stderr)
        return exc.exit_code
    except Exception:  # internal error: traceback, exit 1
        traceback.print_exc()
        return 1


_code = _main()
sys.stdout.flush()
sys.stderr.flush()
os._exit(_code)
