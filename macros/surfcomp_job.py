# SPDX-License-Identifier: LGPL-2.1-or-later
"""Run a surfcomp job file inside ``freecadcmd`` (the FreeCAD route of the batch CLI).

    SURFCOMP_JOB=job.json freecadcmd macros/surfcomp_job.py

The job file is a JSON object with the same names as the CLI (README, "freecadcmd"):
``{"command": "compensate", "nominal": "nominal.step", "measurements": "meas.csv",
"output": "out/corrected.step", "report": "out/report.json", "method": "filtered",
"mask_size": 5}``; relative paths are relative to the job file. Exit codes, messages and
signals as the CLI (:mod:`surfcomp.cli.runner`): 0 ok, 2 bad input (nothing written), 1
internal error, 130/143/129 interrupted, terminated or hung up (nothing written, no
temporary file left).
"""

import contextlib
import os
import signal
import sys

# Ctrl-C while surfcomp is still being imported: FreeCAD's own SIGINT handling would end the
# process with exit 0 (signal.signal puts Python's handler back; the run installs its own)
if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def _main():
    here = os.path.dirname(os.path.abspath(globals().get("__file__") or sys.argv[0]))
    root = os.path.dirname(here)
    if root not in sys.path:
        sys.path.insert(0, root)
    from surfcomp.cli.jobfile import run_job_file

    path = os.environ.get("SURFCOMP_JOB")
    if not path:
        print("surfcomp: error: set SURFCOMP_JOB to the job file (JSON)", file=sys.stderr)
        return 2
    return run_job_file(path)


try:
    _code = _main()
except KeyboardInterrupt:
    print("surfcomp: interrupted; nothing was written", file=sys.stderr)
    _code = 130
for _stream in (sys.stdout, sys.stderr):
    with contextlib.suppress(OSError, ValueError):
        _stream.flush()
os._exit(_code)
