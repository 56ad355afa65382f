# SPDX-License-Identifier: LGPL-2.1-or-later
"""A JSON job file run to its exit code: the body of the ``freecadcmd`` job macro
(``macros/surfcomp_job.py``), with the command line's messages, signals and exit codes
(:mod:`surfcomp.cli.runner`), options named as the job file's keys. The job file is an
input like the others: no output may replace it."""

import contextlib
import sys

from . import runner
from .common import ProgressLine, print_summary, print_written


def run_job_file(path):
    """Run the job file ``path``; returns the exit code."""
    from ..app.file_route import declared_outputs, load_job_file, run_job

    def body():
        job = load_job_file(path)
        to_stdout = any(p == "-" for _o, p in declared_outputs(job))
        with contextlib.redirect_stdout(sys.stderr if to_stdout else sys.stdout):
            comp, rep = run_job(job, progress=ProgressLine(), inputs=[("job file", path)])
            print_summary(comp, rep)
            print_written(job)
        return 0

    return runner.run(body, flags=False)    # messages name the job file's keys
