# SPDX-License-Identifier: LGPL-2.1-or-later
"""Open a user's FreeCAD document (.FCStd) safely, on every route that reads one.

- ``Document.xml`` is checked before FreeCAD sees it (:mod:`surfcomp.io.fcstd`: size limits,
  no DTD or entities), so an entity bomb is refused instead of hanging FreeCAD's parser.
- The proxy modules the document names are imported only when they are FreeCAD's own, an
  installed addon's or an installed package's (:func:`surfcomp.app.fcenv.proxy_module_origin`);
  any other name (a module in the working directory, the standard library) is blocked while
  FreeCAD opens the document, so its objects come back without a proxy and are reported.
- Opened from a plain ``python3``, FreeCAD restores a proxy only when its module is already
  imported (Path's ``PathScripts.PathJob`` is not, and the Job would lose its proxy
  silently): the trusted modules are imported first. On FreeCAD 1.x the CAM modules a 0.20
  document names are aliased to their 1.x homes (:func:`surfcomp.app.cam.alias_legacy_modules`).
"""

import contextlib
import importlib
import importlib.abc
import os
import sys

from ..errors import InputError
from ..io.fcstd import parse_document
from . import cam, fcenv, toolpaths


class _Blocker(importlib.abc.MetaPathFinder):
    """Refuses to find the given modules (and their submodules) while installed."""

    def __init__(self, names):
        self.names = set(names)

    def find_spec(self, fullname, path=None, target=None):
        if fullname in self.names or fullname.split(".")[0] in self.names:
            raise ImportError("surfcomp blocked the import of %s named by the document"
                              % fullname)
        return None


@contextlib.contextmanager
def _blocked(names):
    if not names:
        yield
        return
    blocker = _Blocker(names)
    sys.meta_path.insert(0, blocker)
    try:
        yield
    finally:
        sys.meta_path.remove(blocker)


def prepare_modules(path, info=None):
    """Check ``Document.xml`` and import the proxy modules it names that may be imported.

    Returns
    -------
    (dict, dict)
        ``{module: why it was not imported}`` (untrusted, missing or failing to import),
        and the parsed document info (:func:`surfcomp.io.fcstd.parse_document`).
    """
    info = info or parse_document(path)
    cam.alias_legacy_modules(info["modules"])
    refused = {}
    for name in info["modules"]:
        if name in sys.modules:
            continue
        ok, why = fcenv.proxy_module_origin(name)
        if not ok:
            refused[name] = "not imported: %s" % why
            continue
        try:
            importlib.import_module(name)
        except Exception as exc:  # any import-time error means the proxy cannot restore
            refused[name] = "%s: %s" % (type(exc).__name__, exc)
    return refused, info


def open_document(path, progress_label=None):
    """Open ``path`` hidden after :func:`prepare_modules`; return ``(doc, refused, info)``.

    The caller closes the document (``FreeCAD.closeDocument(doc.Name)``).

    Raises
    ------
    InputError
        Not a FreeCAD document, a hostile ``Document.xml``, or FreeCAD cannot open it.
    """
    FreeCAD = fcenv.import_freecad()
    if not os.path.isfile(path):
        raise InputError("document not found (expected a FreeCAD .FCStd file)", file=path)
    refused, info = prepare_modules(path)
    untrusted = [m for m, why in refused.items() if why.startswith("not imported")]
    try:
        with _blocked(untrusted):
            doc = FreeCAD.openDocument(os.path.abspath(path), True)
    except (OSError, RuntimeError, ValueError) as exc:
        raise InputError("cannot open the FreeCAD document: %s" % exc, file=path) from exc
    return doc, refused, info


def open_in_session(path):
    """The document of this FreeCAD session that has ``path`` open (its file, through any
    link), or None."""
    FreeCAD = fcenv.import_freecad()
    for doc in FreeCAD.listDocuments().values():
        name = getattr(doc, "FileName", "") or ""
        try:
            if name and os.path.samefile(name, path):
                return doc
        except OSError:
            continue
    return None


def open_for_update(path):
    """:func:`open_document` for a route that adds to and changes the document it opens.

    FreeCAD gives back the document already open in this session (the GUI's, a script's)
    instead of reading the file again, so the route would change the user's open document,
    and leave it half changed when it fails: such a document is refused, nothing changed.

    Raises
    ------
    InputError
        The document is open in this session, or as :func:`open_document`.
    """
    if os.path.isfile(path):
        doc = open_in_session(path)
        if doc is not None:
            raise InputError("the document is open in this FreeCAD session (as %s): the "
                             "command would change that open document instead of reading "
                             "the file; nothing was changed. Expected a document that is not "
                             "open here: save and close it first" % doc.Label, file=path)
    return open_document(path)


def restore_failures(doc, path=None, info=None):
    """Objects of an opened document that did not restore completely.

    - Python features (``...::FeaturePython``) whose proxy is None: the proxy's module
      could not (or must not) be imported at open time (e.g. the 3D Surface operation without
      ``ocl``, or a workbench that is not installed);
    - objects listed in the file's ``Document.xml`` (``path``, or its parsed ``info``, see
      :func:`surfcomp.io.fcstd.parse_document`) that are missing from the document (a type
      this FreeCAD does not know).

    Returns
    -------
    list of str
        One description per problem (empty when everything restored).
    """
    problems = toolpaths.lost_proxies(doc.Objects)
    if info is None and path:
        info = parse_document(path)
    if info:
        have = {o.Name for o in doc.Objects}
        for name, typ in info["objects"]:
            if name not in have:
                problems.append("%s (%s): missing after opening (unknown object type?)"
                                % (name, typ))
    return problems


__all__ = ["open_document", "open_for_update", "open_in_session", "prepare_modules",
           "restore_failures"]
