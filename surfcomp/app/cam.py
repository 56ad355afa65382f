# SPDX-License-Identifier: LGPL-2.1-or-later
"""The one place that knows how FreeCAD versions differ: Path (0.20) versus CAM (1.0, 1.1).

Every branch is chosen by looking at what the installed FreeCAD has, never by parsing its
version string, so a build between the releases takes the branch its modules support.

- workbench folder: ``Mod/Path`` (0.20), ``Mod/CAM`` (1.0, 1.1);
- Job, operations, tool controller, preferences, geometry and dressup helpers:
  ``PathScripts.PathJob``, ``PathScripts.PathSurface``, ... (0.20); ``Path.Main.Job``,
  ``Path.Op.Surface``, ``Path.Tool.Controller``, ``Path.Geom``, ``Path.Dressup.Utils``, ...
  (1.x); ``PathScripts.PathUtils`` in all three;
- tool bits: ``Factory.CreateFrom`` of ``PathScripts.PathToolBit`` (0.20) or
  ``Path.Tool.Bit`` (1.0); the asset library ``Path.Tool.toolbit`` with
  ``ToolBit.from_file(...).attach_to_doc(...)`` (1.1);
- post-processors: ``<name>_post.py`` scripts on the workbench's post search path in all
  three, but 0.20 loads them with ``PostProcessor.load`` and 1.x through a factory bound to
  a Job; :func:`load_post` loads the script itself, the same way everywhere;
- OpenCamLib: the PyPI wheel (Debian 12) and Debian's ``python3-opencamlib`` (13 and later)
  both ship ``opencamlib/ocl.so``; 0.20 imports ``ocl``, so that name resolves to it
  (:func:`install_aliases`, from ``Init.py`` at start-up);
- documents saved by 0.20 name their CAM proxies by ``PathScripts.*`` modules that 1.x does
  not have: those names resolve to the 1.x modules (:data:`LEGACY_MODULES`, the same hook);
- Qt: PySide2/Qt5 (0.20, 1.0) or PySide6/Qt6 (1.1); GUI code imports FreeCAD's ``PySide``
  shim only, so it needs no branch here;
- topological naming: 1.x shapes carry an element map (the history of their faces', edges'
  and vertices' names); a shape built from several shapes can come out with names that
  change at every recompute, which breaks the links of CAM operations to its faces
  (:func:`plain_shape` gives it the plain ``FaceN`` names instead); 0.20 has no such map;
- labels: 1.1 counts the labels in use to make new ones unique, and a count can outlive the
  label (a CAM Job's model clone renamed in the GUI): :func:`set_label` puts back a label
  no other object carries without the ``001`` suffix 1.1 would add.

No FreeCADGui: everything here works in ``freecadcmd`` and in a plain ``python3`` once
:func:`setup_workbench` has run.
"""

import contextlib
import importlib
import importlib.util
import os
import sys
from types import SimpleNamespace

from ..errors import GCodeError, InputError
from . import fcenv

#: folders (relative to FreeCAD's home) of the CAM workbench: 0.20 ``Mod/Path``, 1.x ``Mod/CAM``
WORKBENCH_DIRS = (os.path.join("Mod", "Path"), os.path.join("Mod", "CAM"))

#: tool bit file of a ball end mill shipped with every version (its Diameter is set on use)
BALL_END_BIT = "6mm_Ball_End.fctb"

_API = None


# --------------------------------------------------------------------------- environment
def setup_ocl():
    """Make ``import ocl`` work with either OpenCamLib package.

    The PyPI wheel and Debian's ``python3-opencamlib`` both ship the extension as
    ``opencamlib/ocl.so``; FreeCAD 0.20's 3D Surface operation does ``import ocl`` (1.x
    falls back to ``import opencamlib``). :func:`install_aliases` resolves the plain name
    to the packaged module. Returns True when ``ocl`` is importable afterwards.
    """
    install_aliases()
    return _has_module("ocl")


def freecad_home():
    """The FreeCAD resource folder that holds the CAM workbench, or None."""
    for share in fcenv.SHARE_CANDIDATES:
        if any(os.path.isdir(os.path.join(share, d)) for d in WORKBENCH_DIRS):
            return share.rstrip("/") + "/"
    return None


def setup_workbench(require_ocl=True):
    """Make the CAM workbench work from a plain ``python3`` as it works in ``freecadcmd``.

    - puts FreeCAD's ``Mod/*`` and ``Ext`` folders on ``sys.path`` (:func:`fcenv.setup_paths`)
      and OpenCamLib under the name ``ocl``;
    - when FreeCAD is imported as a library, ``FreeCAD.getHomePath()`` is the library
      folder, where the workbench finds no post-processors, tool bits or tool shapes: it is
      made to return the resource folder (inside ``freecadcmd`` it already does).

    Call it before opening a document with CAM objects: an operation whose module cannot be
    imported at open time (e.g. the 3D Surface operation without ``ocl``) loses its proxy.

    Returns
    -------
    str
        FreeCAD's home folder as the workbench now sees it.

    Raises
    ------
    ImportError
        FreeCAD, its CAM workbench or (with ``require_ocl``) OpenCamLib is missing, with
        what to install.
    """
    FreeCAD = fcenv.import_freecad()
    home = FreeCAD.getHomePath()
    if not any(os.path.isdir(os.path.join(home, d)) for d in WORKBENCH_DIRS):
        share = freecad_home()
        if share is None:
            raise ImportError("FreeCAD's CAM (Path) workbench is not installed (looked for "
                              "Mod/Path and Mod/CAM in %s)" % ", ".join(fcenv.SHARE_CANDIDATES))
        home = share
        FreeCAD.getHomePath = lambda: home
    if require_ocl and not setup_ocl():
        raise ImportError("OpenCamLib is not importable as 'ocl' (needed by the 3D Surface "
                          "operation): run tools/install.sh (Debian 13 and later: apt-get "
                          "install python3-opencamlib; Debian 12: python3 -m pip install "
                          "opencamlib)")
    return home


# --------------------------------------------------------------------------- modules
def _has_module(name):
    """Whether ``name`` can be imported (False also when a parent is not a package, as
    0.20's ``Path``, a plain extension module, is for ``Path.Main``)."""
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


#: the CAM modules this project uses, by role, for 1.x and for 0.20
_MODULES_1X = {"Job": "Path.Main.Job", "Surface": "Path.Op.Surface",
               "Profile": "Path.Op.Profile", "ToolController": "Path.Tool.Controller",
               "Preferences": "Path.Preferences", "Geom": "Path.Geom",
               "Dressup": "Path.Dressup.Utils", "PathUtils": "PathScripts.PathUtils",
               "ToolBit": "Path.Tool.Bit", "toolbit": "Path.Tool.toolbit",
               "Custom": "Path.Op.Custom", "Log": "Path.Log"}
_MODULES_020 = {"Job": "PathScripts.PathJob", "Surface": "PathScripts.PathSurface",
                "Profile": "PathScripts.PathProfile",
                "ToolController": "PathScripts.PathToolController",
                "Preferences": "PathScripts.PathPreferences", "Geom": "PathScripts.PathGeom",
                "Dressup": "PathScripts.PathDressup", "PathUtils": "PathScripts.PathUtils",
                "ToolBit": "PathScripts.PathToolBit", "Custom": "PathScripts.PathCustom",
                "Log": "PathScripts.PathLog"}


def api():
    """Which branch each difference takes on the installed FreeCAD, found once.

    Returns
    -------
    types.SimpleNamespace
        ``modules``: ``'Path'`` (1.x: ``Path.Main``, ``Path.Op``, ...) or ``'PathScripts'``
        (0.20); ``toolbits``: ``'library'`` (1.1's ``Path.Tool.toolbit``) or ``'Factory'``
        (``Factory.CreateFrom``); ``names``: module name by role (see :func:`module`).
    """
    global _API
    if _API is None:
        setup_workbench(require_ocl=False)
        setup_ocl()      # the 3D Surface operation's module needs it at import time
        if _has_module("Path.Main"):
            modules, names = "Path", dict(_MODULES_1X)
        else:
            modules, names = "PathScripts", dict(_MODULES_020)
        toolbits = "library" if _has_module(names.get("toolbit", "")) else "Factory"
        _API = SimpleNamespace(modules=modules, toolbits=toolbits, names=names)
    return _API


def module(role):
    """The CAM module that plays ``role`` (``'Job'``, ``'Surface'``, ``'Profile'``,
    ``'ToolController'``, ``'Preferences'``, ``'Geom'``, ``'Dressup'``, ``'PathUtils'``,
    ``'ToolBit'``, ``'toolbit'``, ``'Custom'``, ``'Log'``) on this FreeCAD, imported on first
    use."""
    return importlib.import_module(api().names[role])


@contextlib.contextmanager
def logged_errors():
    """``with logged_errors() as messages:`` the errors the CAM workbench logs while the
    block runs, appended to ``messages`` as they come.

    CAM operations report many failures only through their log and then return, so FreeCAD
    marks the object recomputed without error while its path is an old or a truncated one:
    any operation's "No Tool Controller is selected", the 3D Surface operation's "Failed to
    pre-process model and/or selected face(s)". The log module (``PathScripts.PathLog``,
    ``Path.Log``: the same in every version) writes every message through its ``_log``;
    that function is wrapped for the block, so the messages still reach FreeCAD's console
    as before, and the calling module the log names is unchanged."""
    log = module("Log")
    real = log._log
    messages = []

    def _log(level, where, msg):
        if level == log.Level.ERROR:
            messages.append(str(msg).strip())
        return real(level, where, msg)

    log._log = _log
    try:
        yield messages
    finally:
        log._log = real


def branches():
    """``{'modules': ..., 'toolbits': ..., 'qt': ...}``: which branch each difference takes
    on this FreeCAD (for messages, the test matrix and bug reports)."""
    a = api()
    qt = "PySide6" if _has_module("PySide6") else "PySide2"
    return {"modules": a.modules, "toolbits": a.toolbits, "qt": qt}


# --------------------------------------------------------------------------- objects
def create_job(doc, models, name="Job"):
    """A Job on ``models`` (document objects); CAM clones them into ``Job.Model``."""
    import FreeCAD

    if FreeCAD.ActiveDocument is None or FreeCAD.ActiveDocument.Name != doc.Name:
        FreeCAD.setActiveDocument(doc.Name)
    job = module("Job").Create(name, list(models), None)
    doc.recompute()
    return job


def create_operation(kind, name, job=None):
    """A new operation of ``kind`` (``'Surface'`` or ``'Profile'``) in ``job`` (default:
    the document's only job)."""
    return module(kind).Create(name, parentJob=job)


def add_operation(job, op):
    """Put the operation ``op`` into ``job``'s Operations (the same call in every version)."""
    job.Proxy.addOperation(op)


def workbench_file(*parts):
    """A file shipped with the CAM workbench (e.g. ``('Tools', 'Bit', name)``)."""
    import FreeCAD

    home = FreeCAD.getHomePath()
    for sub in WORKBENCH_DIRS:
        path = os.path.join(home, sub, *parts)
        if os.path.isfile(path):
            return path
    raise InputError("the CAM workbench file %s is not installed (looked under %s)"
                     % (os.path.join(*parts), home))


def create_tool_bit(doc, bit_file, label):
    """A tool bit document object made from a shipped ``.fctb`` file."""
    path = workbench_file("Tools", "Bit", bit_file)
    if api().toolbits == "library":
        return module("toolbit").ToolBit.from_file(path).attach_to_doc(doc, label=label)
    import FreeCAD

    if FreeCAD.ActiveDocument is None or FreeCAD.ActiveDocument.Name != doc.Name:
        FreeCAD.setActiveDocument(doc.Name)
    return module("ToolBit").Factory.CreateFrom(path, label)


def create_tool_controller(name, bit, number=1):
    """A tool controller for ``bit`` (in the active document)."""
    return module("ToolController").Create(name, bit, number)


def find_parent_job(obj):
    """The Job an operation or dressup belongs to, or None."""
    return module("PathUtils").findParentJob(obj)


def placed_commands(op):
    """The commands of an operation's Path with its placement applied (0.20 has no
    ``getPathWithPlacement``: its operations carry no placement of their own)."""
    placed = getattr(module("PathUtils"), "getPathWithPlacement", None)
    return (placed(op) if placed is not None else op.Path).Commands


def base_operation(obj):
    """The operation under a chain of dressups (``obj`` itself for an operation)."""
    return module("Dressup").baseOp(obj)


#: the names FreeCAD gives a ball end mill's shape (:func:`tool_shape`)
BALL_END_SHAPES = ("ballend", "ballendmill")


def tool_shape(tool):
    """The lower-case name of a tool's shape (``ballend``, ``endmill``, ``bullnose`` ...):
    1.1's ``ShapeID``/``ShapeType``, 0.20's and 1.0's ``ShapeName`` (or the name of its
    ``BitShape`` file), a legacy tool's ``ToolType`` (``ballendmill``); None when the tool
    names none."""
    for prop in ("ShapeID", "ShapeType", "ShapeName", "BitShape", "ToolType"):
        value = getattr(tool, prop, None)
        if isinstance(value, str) and value.strip():
            return os.path.splitext(os.path.basename(value.strip()))[0].lower()
    return None


def edge_for_command(cmd, start):
    """The Part edge a move command draws from ``start`` (FreeCAD.Vector), or None."""
    return module("Geom").edgeForCmd(cmd, start)


def command_end_point(cmd, start):
    """Where a command leaves the tool, from ``start``."""
    return module("Geom").commandEndPoint(cmd, start)


def plain_shape(shape):
    """``shape`` with its sub-elements named by their index only, as a shape read from a
    file: on 1.x the shape read back from its BREP text (the same geometry to the last
    digit, no element map); on 0.20 (no element map) ``shape``.

    A shape assembled from separately built faces (the region's corrected faces, sewn into
    their solid, :mod:`surfcomp.app.region_retrim`) has, on 1.x, an element map in which
    several faces descend from the same ``Face1`` (each was the one face of its own shape).
    FreeCAD tells such duplicates apart by a tag (``Face1;D1a18;...``) drawn from the
    document's string table, so a feature recomputed from it (Draft's clone: a CAM Job's
    model) gets a new name for those faces at every recompute. The links of the Job's
    operations to them then miss, FreeCAD looks for the face by geometry instead
    (``Part::Feature::searchElementCache``), and OpenCASCADE fails comparing the old and
    the new B-spline surfaces: the clone reports "Unknown C++ exception". A shape without
    an element map gets the plain names (``Face1;:H<tag>,F``) from the feature that holds
    it, the same at every recompute, as a nominal's. Clearing the map of a copy
    (``ElementMap = {}``) is not the same: that shape counts as mapped, with no names, so a
    clone of it names no faces and its links miss as well.
    """
    if not hasattr(shape, "ElementMap"):
        return shape
    import Part

    out = Part.Shape()
    out.importBrepFromString(shape.exportBrepToString())
    return out


def set_label(obj, label):
    """Give ``obj`` the label ``label`` exactly when no other object of its document carries
    it; when one does, FreeCAD makes it unique as usual (a number suffix).

    FreeCAD 1.1 keeps a count of the labels in use; in the GUI a CAM Job's model clone
    renamed once left its old label counted after the rename, so giving the old label back
    (Restore nominal) produced "Model-Block001" although no object was called "Model-Block".
    The label checked free here is set with the duplicate check off for this assignment
    (FreeCAD's ``DuplicateLabels`` preference, put back at once); 0.20 and 1.0 set it the
    same either way.
    """
    if any(o.Name != obj.Name and o.Label == label for o in obj.Document.Objects):
        obj.Label = label
        return
    import FreeCAD

    prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Document")
    had = "DuplicateLabels" in prefs.GetBools()
    kept = prefs.GetBool("DuplicateLabels", False)
    prefs.SetBool("DuplicateLabels", True)
    try:
        obj.Label = label
    finally:
        if had:
            prefs.SetBool("DuplicateLabels", kept)
        else:
            prefs.RemBool("DuplicateLabels")


# --------------------------------------------------------------------------- post-processing
def available_posts():
    """Names of the post-processors the workbench finds (without ``_post``)."""
    return sorted(module("Preferences").allAvailablePostProcessors())


def load_post(name):
    """A fresh copy of the post-processor script ``<name>_post.py``.

    Scripts keep their options in module globals, so each call loads the file anew (as
    0.20's ``PostProcessor.load`` reloads it); the module's ``export(objects, filename,
    argstring)`` returns the G-code text when ``filename`` is ``'-'``.

    Raises
    ------
    GCodeError
        No such post-processor, or it is not a script with ``export``.
    """
    names = available_posts()
    if name not in names:
        raise GCodeError("unknown post-processor %r (available: %s)" % (name, ", ".join(names)))
    for folder in list(module("Preferences").searchPathsPost()) + list(sys.path):
        path = os.path.join(folder or ".", "%s_post.py" % name)
        if not os.path.isfile(path):
            continue
        spec = importlib.util.spec_from_file_location("%s_post" % name, path)
        script = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(script)
        if not callable(getattr(script, "export", None)):
            raise GCodeError("post-processor %r (%s) has no export() function; only script "
                             "post-processors are supported" % (name, path))
        return script
    raise GCodeError("post-processor %r is listed but its file was not found" % name)


def native_post(job, name, args):
    """The program FreeCAD's own Post Process command writes for ``job`` with the post
    ``name`` and arguments ``args`` (its object list, fixtures and tool changes, not
    :func:`surfcomp.app.cam_job.post_list`'s): 1.x through ``PostProcessorFactory`` with the
    Job's ``PostProcessorArgs`` set to ``args`` for the call; 0.20 through the Post command's
    ``buildPostList`` and the script's ``export`` (``PathScripts.PathPost`` imports
    FreeCADGui, which ``freecadcmd`` also has). Returns the text of every output file joined.
    """
    if api().modules == "Path":
        from Path.Post.Processor import PostProcessorFactory

        old = job.PostProcessorArgs
        job.PostProcessorArgs = args
        try:
            sections = PostProcessorFactory.get_post_processor(job, name).export()
        finally:
            job.PostProcessorArgs = old
        return "".join(text for _name, text in sections or ())
    from PathScripts.PathPost import CommandPathPost

    return "".join(load_post(name).export(objs, "-", args) or ""
                   for objs in CommandPathPost().buildPostList(job))


# --------------------------------------------------------------------------- 0.20 documents
#: modules of FreeCAD 0.20's Path workbench named by the proxies in documents it saved, and
#: the 1.x modules holding the same classes (FreeCAD 1.x itself restores none of them)
LEGACY_MODULES = {
    "PathScripts.PathJob": "Path.Main.Job",
    "PathScripts.PathStock": "Path.Main.Stock",
    "PathScripts.PathSetupSheet": "Path.Base.SetupSheet",
    "PathScripts.PathToolController": "Path.Tool.Controller",
    "PathScripts.PathToolBit": "Path.Tool.Bit",
    "PathScripts.PathSurface": "Path.Op.Surface",
    "PathScripts.PathWaterline": "Path.Op.Waterline",
    "PathScripts.PathProfile": "Path.Op.Profile",
    "PathScripts.PathPocket": "Path.Op.Pocket",
    "PathScripts.PathPocketShape": "Path.Op.PocketShape",
    "PathScripts.PathMillFace": "Path.Op.MillFace",
    "PathScripts.PathAdaptive": "Path.Op.Adaptive",
    "PathScripts.PathDrilling": "Path.Op.Drilling",
    "PathScripts.PathHelix": "Path.Op.Helix",
    "PathScripts.PathEngrave": "Path.Op.Engrave",
    "PathScripts.PathDeburr": "Path.Op.Deburr",
    "PathScripts.PathVcarve": "Path.Op.Vcarve",
    "PathScripts.PathSlot": "Path.Op.Slot",
    "PathScripts.PathCustom": "Path.Op.Custom",
    "PathScripts.PathProbe": "Path.Op.Probe",
    "PathScripts.PathThreadMilling": "Path.Op.ThreadMilling",
    "PathScripts.PathDressupPathBoundary": "Path.Dressup.Boundary",
    "PathScripts.PathDressupHoldingTags": "Path.Dressup.Tags",
}


#: every alias :func:`install_aliases` resolves: OpenCamLib's plain name and 0.20's CAM modules
ALIASES = dict(LEGACY_MODULES, ocl="opencamlib.ocl")


class _AliasLoader:
    """Loads an alias as the module it stands for (one module object under two names).

    The import machinery asks a loader only for these two methods; deriving from
    ``importlib.abc.Loader`` would import ``importlib.resources``, ``pathlib`` and
    ``typing`` at every start (docs/benchmarks.md, "Costs behind choices in the code")."""

    def __init__(self, target):
        self.target = target
        self._spec = None

    def create_module(self, spec):
        module = importlib.import_module(self.target)
        self._spec = module.__spec__
        return module

    def exec_module(self, module):
        # the import machinery set the alias's spec on the module: give it its own back
        module.__spec__ = self._spec


class _AliasFinder:
    """Last on ``sys.meta_path``: asked only for names no other finder found (by
    ``find_spec``, all the machinery needs of a finder).

    ``ocl`` resolves to ``opencamlib.ocl``; a 0.20 CAM module name (:data:`LEGACY_MODULES`)
    to its 1.x home. On 0.20 every legacy name exists and ``ocl`` may too, so it is never
    asked for them; a target this FreeCAD lacks leaves the name unresolved as before.
    """

    def find_spec(self, fullname, path=None, target=None):
        new = ALIASES.get(fullname)
        if new is None or not _has_module(new):
            return None
        return importlib.util.spec_from_loader(fullname, _AliasLoader(new))


def install_aliases():
    """Resolve ``ocl`` and 0.20's CAM module names on demand (idempotent, imports nothing).

    Called from ``Init.py`` when FreeCAD starts (GUI and ``freecadcmd``), so documents that
    FreeCAD itself opens restore their 3D Surface operations (which import ``ocl``) and, on
    1.x, the CAM objects a 0.20 document names by ``PathScripts.PathJob`` and so on. Nothing
    is imported until something imports one of the names.
    """
    if not any(isinstance(f, _AliasFinder) for f in sys.meta_path):
        sys.meta_path.append(_AliasFinder())


def alias_legacy_modules(names):
    """Let a document saved by FreeCAD 0.20 restore its CAM objects on 1.x.

    ``names``: the proxy modules the document names (its ``Document.xml``).

    0.20 saved each Path object's proxy as ``PathScripts.PathJob.ObjectJob`` and so on;
    1.x moved the classes (same names) to ``Path.*`` and, by itself, cannot restore those
    proxies, so the Job, its tools and operations would come back as dead objects. With
    :func:`install_aliases` each such name resolves to the module that holds the classes
    now; the classes' own ``onDocumentRestored`` then bring the properties up to date. Does
    nothing on 0.20. Returns ``{old: new}`` for the names of ``names`` that resolve to
    another module.
    """
    install_aliases()
    done = {}
    for old in names:
        new = LEGACY_MODULES.get(old)
        if new is None or not _has_module(old):
            continue
        module = importlib.import_module(old)
        if module.__name__ != old:
            done[old] = module.__name__
    return done
