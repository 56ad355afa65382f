"""Make FreeCAD importable from a plain ``python3`` and set up what ``freecadcmd`` sets up.

Importing FreeCAD as a library (``/usr/bin/python3`` with the FreeCAD lib folder on
``sys.path``) leaves FreeCAD's ``Mod`` and ``Ext`` folders off ``sys.path``, so Path,
its post-processors and ``freecad.*`` namespace packages are only half there. This
module puts them on the path. It is idempotent and cheap to call repeatedly.

This is the one module of ``surfcomp.app`` that may be imported before FreeCAD is.
"""

import glob
import importlib
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
    """Put FreeCAD's lib, Mod/* and Ext folders and OpenCamLib on ``sys.path``."""
    if "FreeCAD" not in sys.modules:
        lib = freecad_lib_dir()
        if lib:
            _add(lib)
    for share in SHARE_CANDIDATES:
        for mod in sorted(glob.glob(os.path.join(share, "Mod", "*"))):
            _add(mod)
        _add(os.path.join(share, "Ext"))
        _add(os.path.join(share, "Mod"))
    setup_ocl()


def setup_ocl():
    """Make ``import ocl`` work with the PyPI ``opencamlib`` wheel.

    The wheel ships the extension as ``opencamlib/ocl.so`` while FreeCAD's Path
    does ``import ocl``; we register the packaged module under the plain name.
    Returns True when ``ocl`` is importable afterwards.
    """
    if "ocl" in sys.modules:
        return True
    try:
        spec = importlib.util.find_spec("ocl")
    except (ImportError, ValueError):
        spec = None
    if spec is not None:
        return True
    try:
        mod = importlib.import_module("opencamlib.ocl")
    except ImportError:
        return False
    sys.modules["ocl"] = mod
    return True


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


#: folders (relative to FreeCAD's home) of the Path workbench: 0.20 ``Mod/Path``, 1.x ``Mod/CAM``
PATH_MODULE_DIRS = (os.path.join("Mod", "Path"), os.path.join("Mod", "CAM"))


def freecad_home():
    """The FreeCAD resource folder that holds ``Mod/Path`` (or ``Mod/CAM``), or None."""
    for share in SHARE_CANDIDATES:
        if any(os.path.isdir(os.path.join(share, d)) for d in PATH_MODULE_DIRS):
            return share
    return None


def setup_path_workbench(require_ocl=True):
    """Make Path (CAM) work from a plain ``python3`` as it works in ``freecadcmd``.

    - puts FreeCAD's ``Mod/*`` and ``Ext`` folders and OpenCamLib on ``sys.path``
      (:func:`setup_paths`);
    - when FreeCAD is imported as a library, ``FreeCAD.getHomePath()`` is the library
      folder, where Path finds no post-processors, tool bits or tool shapes: it is made
      to return the resource folder that holds ``Mod/Path`` (inside ``freecadcmd`` it
      already does and is left alone).

    Call it before opening a document with Path objects: an operation whose module
    cannot be imported at open time (e.g. the 3D Surface operation without ``ocl``)
    loses its proxy silently.

    Parameters
    ----------
    require_ocl : bool
        Raise when OpenCamLib is not importable as ``ocl``.

    Returns
    -------
    str
        FreeCAD's home folder as Path now sees it.

    Raises
    ------
    ImportError
        FreeCAD, its Path workbench or (with ``require_ocl``) OpenCamLib is missing, with
        what to install.
    """
    FreeCAD = import_freecad()
    home = FreeCAD.getHomePath()
    if not any(os.path.isdir(os.path.join(home, d)) for d in PATH_MODULE_DIRS):
        share = freecad_home()
        if share is None:
            raise ImportError("FreeCAD's Path workbench is not installed (looked for Mod/Path "
                              "in %s)" % ", ".join(SHARE_CANDIDATES))
        home = share.rstrip("/") + "/"
        FreeCAD.getHomePath = lambda: home
    if require_ocl and not setup_ocl():
        raise ImportError("OpenCamLib is not importable as 'ocl' (needed by Path's 3D Surface "
                          "operation): run tools/install.sh or 'python3 -m pip install "
                          "opencamlib'")
    return home
