# SPDX-License-Identifier: LGPL-2.1-or-later
"""Make FreeCAD importable from a plain ``python3`` and set up what ``freecadcmd`` sets up.

Importing FreeCAD as a library (``/usr/bin/python3`` with the FreeCAD lib folder on
``sys.path``) leaves FreeCAD's ``Mod`` and ``Ext`` folders off ``sys.path``, so Path,
its post-processors and ``freecad.*`` namespace packages are only half there. This
module puts them on the path. It is idempotent and cheap to call repeatedly. The folders
are the same for every FreeCAD version; what differs between versions is in
:mod:`surfcomp.app.cam`.

This is the one module of ``surfcomp.app`` that may be imported before FreeCAD is.
"""

import glob
import os
import sys

#: where Debian 12 and most Linux packages put FreeCAD; ``FREECAD_LIB`` overrides
LIB_CANDIDATES = (
    "/usr/lib/freecad-python3/lib",
    "/usr/lib/freecad/lib",
    "/usr/local/lib/freecad/lib",
    "/usr/local/lib",
)
SHARE_CANDIDATES = ("/usr/share/freecad", "/usr/local/share/freecad")


def _add(path):
    if os.path.isdir(path) and path not in sys.path:
        sys.path.append(path)


def freecad_lib_dir():
    """Return the folder holding ``FreeCAD.so`` (or None when none is found)."""
    env = os.environ.get("FREECAD_LIB")
    for cand in ([env] if env else []) + list(LIB_CANDIDATES):
        if cand and os.path.exists(os.path.join(cand, "FreeCAD.so")):
            return cand
    return None


def setup_paths():
    """Put FreeCAD's lib, Mod/* and Ext folders on ``sys.path``."""
    if "FreeCAD" not in sys.modules:
        lib = freecad_lib_dir()
        if lib:
            _add(lib)
    for share in SHARE_CANDIDATES:
        for mod in sorted(glob.glob(os.path.join(share, "Mod", "*"))):
            _add(mod)
        _add(os.path.join(share, "Ext"))
        _add(os.path.join(share, "Mod"))


def import_freecad():
    """Import and return the ``FreeCAD`` module, setting up paths first.

    Raises
    ------
    ImportError
        With a message that says how to install FreeCAD.
    """
    setup_paths()
    first = "FreeCAD" not in sys.modules
    try:
        import FreeCAD  # noqa: F401  (imported for the side effect and returned)
    except ImportError as exc:
        raise ImportError(
            "FreeCAD is not importable (%s). Install it with 'apt-get install "
            "freecad-python3' or set FREECAD_LIB to the folder holding FreeCAD.so." % exc
        ) from exc
    import FreeCAD
    if first:
        _keep_python_sigint()
    return FreeCAD


def _keep_python_sigint():
    """Give Ctrl-C back to Python after FreeCAD was imported as a library.

    FreeCAD 1.1 installs its own SIGINT handler when it is imported, below Python's, so
    Ctrl-C no longer raised KeyboardInterrupt: an interrupted job went on and wrote its
    files. Python's handler (whatever Python code had set) is installed again.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return
    handler = signal.getsignal(signal.SIGINT)
    if callable(handler):
        signal.signal(signal.SIGINT, handler)


def _user_mod_dirs():
    home = os.path.expanduser("~")
    dirs = [os.path.join(os.environ.get("XDG_DATA_HOME", os.path.join(home, ".local", "share")),
                         "FreeCAD", "Mod"),
            os.path.join(home, ".FreeCAD", "Mod")]
    try:
        import FreeCAD

        dirs.append(os.path.join(FreeCAD.getUserAppDataDir(), "Mod"))
    except (ImportError, AttributeError):
        pass
    return dirs


def _trusted_roots():
    """Folders a document's proxy module may come from: FreeCAD's own (lib, Mod, Ext), the
    user's addon folders and the installed Python packages (site/dist-packages)."""
    roots = [d for d in (freecad_lib_dir(),) if d]
    for share in SHARE_CANDIDATES:
        roots += [os.path.join(share, "Mod"), os.path.join(share, "Ext")]
    roots += _user_mod_dirs()
    roots += [p for p in sys.path if os.path.basename(p) in ("dist-packages", "site-packages")]
    return [os.path.realpath(r) for r in roots if r and os.path.isdir(r)]


def _inside(path, roots):
    path = os.path.realpath(path)
    return any(path == r or path.startswith(r + os.sep) for r in roots)


def proxy_module_origin(name):
    """Where a document's proxy module ``name`` would be imported from, or the reason it
    must not be imported.

    Only FreeCAD's own modules, installed addons (the user's Mod folders) and installed
    Python packages are trusted; a module found anywhere else (the working directory, which
    ``python3 -m`` puts on ``sys.path``, or the standard library: a document naming
    ``this`` or ``os`` is not a FreeCAD document) is refused. The top-level package is
    looked up without being imported.

    Returns
    -------
    (bool, str)
        ``(True, folder)`` when the module may be imported, else ``(False, reason)``.
    """
    import importlib.util

    top = name.split(".")[0]
    if not top.isidentifier() or not all(p.isidentifier() for p in name.split(".")):
        return False, "not a module name"
    if top == "surfcomp":
        return True, os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if top in sys.modules:
        mod = sys.modules[top]
        where = getattr(mod, "__file__", None) or next(iter(getattr(mod, "__path__", [])), None)
    else:
        try:
            spec = importlib.util.find_spec(top)
        except (ImportError, ValueError):
            spec = None
        if spec is None:
            return False, "no such module"
        where = spec.origin if spec.origin not in (None, "namespace") else next(
            iter(spec.submodule_search_locations or []), None)
    if where in (None, "built-in", "frozen"):
        return False, "a built-in module, not a FreeCAD module"
    if not _inside(where, _trusted_roots()):
        return False, "found in %s, which is neither FreeCAD's nor an installed addon's " \
                      "folder" % os.path.dirname(where)
    return True, os.path.dirname(where)
