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
    try:
        import FreeCAD  # noqa: F401  (imported for the side effect and returned)
    except ImportError as exc:
        raise ImportError(
            "FreeCAD is not importable (%s). Install it with 'apt-get install "
            "freecad-python3' or set FREECAD_LIB to the folder holding FreeCAD.so." % exc
        ) from exc
    import FreeCAD
    return FreeCAD
