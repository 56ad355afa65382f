# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp``: the batch command line."""

import importlib.util
import sys


def _missing():
    """The numeric packages this Python lacks (another Python first on ``PATH``, such as a
    pyenv or a venv, usually has neither FreeCAD nor Debian's numpy and scipy)."""
    out = []
    for name in ("numpy", "scipy"):
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):
            found = False
        if not found:
            out.append(name)
    return out


#: the variables by which a user sets the BLAS library's threads (OpenBLAS reads them in
#: this order: the first one set counts)
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")
#: the commands whose linear algebra is small (measured: the outputs the same bytes, the
#: CPU lower or unchanged; ``simulate`` was not shown to gain, so it keeps the default)
ONE_BLAS_THREAD_COMMANDS = ("compensate", "inspect")


def one_blas_thread(environ, argv):
    """Give numpy's BLAS one thread in this process (``OPENBLAS_NUM_THREADS=1`` in
    ``environ``, before numpy is imported) for a command of
    :data:`ONE_BLAS_THREAD_COMMANDS` (``argv``: the arguments after ``-m surfcomp``)
    unless the user set its threads; True when it was set.

    Their linear algebra is small (a face of 49 x 49 poles) or already runs on the cores
    in chunks (:mod:`surfcomp.core.chunks`). OpenBLAS's worker thread then only waits:
    after each call it made parallel it spins in ``sched_yield`` on the other core (8 459
    calls in one ``compensate -o`` of the example, none with one thread): on an idle
    machine that command's CPU time was well above its wall time, with no other thread of
    it at work (docs/benchmarks.md, "Costs behind choices in the code"). The outputs are
    the same bytes."""
    if not argv or argv[0] not in ONE_BLAS_THREAD_COMMANDS:
        return False
    if any(name in environ for name in BLAS_THREAD_VARIABLES):
        return False
    environ["OPENBLAS_NUM_THREADS"] = "1"
    return True


def _owns_the_process():
    """True when Python was started to run this command (``python3 -m surfcomp``, as the
    ``surfcomp`` launcher does), False when another program runs this module in its own
    process (``runpy``) and goes on after it."""
    argv = getattr(sys, "orig_argv", None) or []
    return any(a == "-m" and b == "surfcomp" for a, b in zip(argv, argv[1:]))


if __name__ == "__main__":
    lacking = _missing()
    if lacking:
        print("surfcomp: error: this Python (%s) has no %s; run 'surfcomp' or "
              "'/usr/bin/python3 -m surfcomp' (Debian's Python, set up by tools/install.sh)"
              % (sys.executable or "python3", " or ".join(lacking)), file=sys.stderr)
        sys.exit(2)
    import gc
    import os

    owned = _owns_the_process()
    if owned:   # before anything imports numpy
        one_blas_thread(os.environ, sys.argv[1:])
    from surfcomp.cli import main
    from surfcomp.core.memory import one_command_process

    if owned:
        one_command_process()
    code = main()
    # the process ends here: the interpreter's exit need not search the objects still alive
    # (numpy's, scipy's, FreeCAD's) for reference cycles (docs/benchmarks.md, "Costs
    # behind choices in the code")
    gc.freeze()
    sys.exit(code)
