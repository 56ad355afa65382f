# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp``: the batch command line."""

import importlib.util
import os
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


def _owns_the_process():
    """True when Python was started to run this command (``python3 -m surfcomp``, as the
    ``surfcomp`` launcher does), False when another program runs this module in its own
    process (``runpy``) and goes on after it."""
    argv = getattr(sys, "orig_argv", None) or []
    return any(a == "-m" and b == "surfcomp" for a, b in zip(argv, argv[1:]))


def _busy_threads():
    """Threads the interpreter's exit would wait for: any but the main thread, the daemons
    and the idle workers of the chunk pools (:mod:`surfcomp.core.chunks`, whose calls
    return only once all their chunks are done)."""
    import threading

    return [t for t in threading.enumerate()
            if t is not threading.main_thread() and not t.daemon
            and not t.name.startswith("surfcomp-chunk")]


if __name__ == "__main__":
    lacking = _missing()
    if lacking:
        print("surfcomp: error: this Python (%s) has no %s; run 'surfcomp' or "
              "'/usr/bin/python3 -m surfcomp' (Debian's Python, set up by tools/install.sh)"
              % (sys.executable or "python3", " or ".join(lacking)), file=sys.stderr)
        sys.exit(2)
    import gc

    from surfcomp.cli import main
    from surfcomp.core.memory import one_command_process

    owned = _owns_the_process()
    if owned:
        one_command_process()
    code = main()
    # the process ends here: the interpreter's exit need not search the objects still alive
    # (numpy's, scipy's, FreeCAD's) for reference cycles, which took 0.04 s of CPU
    gc.freeze()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):   # the interpreter's own exit says so, as it always did
        sys.exit(code)
    if not owned or _busy_threads():
        sys.exit(code)
    # every output is committed and closed and nothing else runs: the modules' teardown at
    # the interpreter's exit (numpy's, scipy's, FreeCAD's) would only free memory
    # that the system takes back anyway
    os._exit(code)
