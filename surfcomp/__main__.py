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

    from surfcomp.cli import main
    from surfcomp.core.memory import one_command_process

    owned = _owns_the_process()
    if owned:
        one_command_process()
    code = main()
    # the process ends here: the interpreter's exit need not search the objects still alive
    # (numpy's, scipy's, FreeCAD's) for reference cycles, which took 0.04 s of CPU
    gc.freeze()
    sys.exit(code)
