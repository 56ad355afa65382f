# SPDX-License-Identifier: LGPL-2.1-or-later
"""FreeCAD's progress indicator as a core ``progress(fraction, message)`` callback.

In the GUI it drives the status bar's progress bar (Esc interrupts: the callback raises
:class:`surfcomp.errors.Cancelled`, which the core lets propagate before anything is
written); in ``freecadcmd`` FreeCAD's console sequencer does nothing visible.
"""

import contextlib

from ..errors import Cancelled

STEPS = 100


class FreeCADProgress:
    """Callable ``progress(fraction, message)`` advancing a ``Base.ProgressIndicator``."""

    def __init__(self, FreeCAD, title):
        self._bar = FreeCAD.Base.ProgressIndicator()
        self._bar.start(title, STEPS)
        self._done = 0

    def __call__(self, fraction, message=""):
        target = min(STEPS, int(fraction * STEPS))
        while self._done < target:
            try:
                self._bar.next(True)  # True: the user may abort (Esc in the GUI)
            except Exception as exc:  # FreeCAD raises its abort as a plain exception
                if "abort" in str(exc).lower() or "cancel" in str(exc).lower():
                    raise Cancelled("interrupted by the user; nothing was changed") from exc
                raise
            self._done += 1

    def stop(self):
        self._bar.stop()


@contextlib.contextmanager
def freecad_progress(title):
    """``with freecad_progress("Compensating ...") as progress:`` -> a core callback."""
    from . import fcenv

    bar = FreeCADProgress(fcenv.import_freecad(), title)
    try:
        yield bar
    finally:
        bar.stop()


def dependency_order(doc):
    """The objects of ``doc``, each after everything it links (its ``OutList``).

    (``doc.TopologicalSortedObjects`` lists them the other way round on FreeCAD 0.20.)
    """
    order, seen = [], set()
    for root in doc.Objects:
        stack = [(root, iter(root.OutList))]
        if root.Name in seen:
            continue
        seen.add(root.Name)
        while stack:
            obj, deps = stack[-1]
            dep = next((d for d in deps if d.Name not in seen), None)
            if dep is None:
                stack.pop()
                order.append(obj)
            else:
                seen.add(dep.Name)
                stack.append((dep, iter(dep.OutList)))
    return order


def pending(doc):
    """The objects of ``doc`` that need a recompute (touched, or depending on one that is),
    in dependency order."""
    todo, names = [], set()
    for o in dependency_order(doc):
        if "Touched" in o.State or any(x.Name in names for x in o.OutList):
            todo.append(o)
            names.add(o.Name)
    return todo


def is_path_generator(obj):
    """Whether ``obj`` computes a tool path: a CAM operation (its proxy has FreeCAD's
    ``opExecute``) or a dressup of one (its ``Base`` is such an object)."""
    if "Path" not in obj.PropertiesList or obj.getTypeIdOfProperty("Path") != "Path::PropertyPath":
        return False
    if hasattr(getattr(obj, "Proxy", None), "opExecute"):
        return True
    base = getattr(obj, "Base", None) if "Base" in obj.PropertiesList else None
    return hasattr(base, "PropertiesList") and is_path_generator(base)


#: the errors the CAM workbench logged at the last recompute of each tool path generator
#: that logged any: ``{(document name, object name): [message, ...]}``
_CAM_ERRORS = {}


def cam_errors(obj):
    """The errors the CAM workbench logged while :func:`recompute_one` last recomputed
    ``obj`` (empty: none, or not recomputed there)."""
    return list(_CAM_ERRORS.get((obj.Document.Name, obj.Name), ()))


def forget_cam_errors(doc):
    """Drop what :func:`cam_errors` holds for the objects of ``doc`` (a new command starts:
    an operation it does not recompute has no error of its own to report)."""
    for key in [k for k in _CAM_ERRORS if k[0] == doc.Name]:
        del _CAM_ERRORS[key]


def state_text(obj):
    """Why ``obj`` failed to recompute (the errors the CAM workbench logged for it, else its
    status, else its state)."""
    logged = cam_errors(obj)
    if logged:
        return "the CAM workbench reported: " + "; ".join(logged)
    status = obj.getStatusString() if hasattr(obj, "getStatusString") else ""
    return status or ", ".join(obj.State)


def failed(obj):
    """Whether the last recompute of ``obj`` failed: it is in error, or (a tool path
    generator) the CAM workbench logged an error while :func:`recompute_one` computed it,
    which leaves it marked recomputed without error (:func:`surfcomp.app.cam.logged_errors`)."""
    return bool({"Invalid", "Error"} & set(obj.State)) or bool(cam_errors(obj))


def recompute_one(obj):
    """Recompute ``obj`` alone, once, and mark it recomputed as ``doc.recompute()`` does
    (``obj.recompute()`` leaves the object touched, so a later ``doc.recompute()`` would
    compute it a second time). Returns False when it failed (:func:`failed`; it stays
    touched, and :func:`state_text` says why)."""
    key = (obj.Document.Name, obj.Name)
    _CAM_ERRORS.pop(key, None)
    if is_path_generator(obj):
        from . import cam

        with cam.logged_errors() as logged:
            obj.recompute()
        if logged:
            _CAM_ERRORS[key] = logged
    else:
        obj.recompute()
    ok = not failed(obj)
    if ok:
        obj.purgeTouched()
    return ok


def recompute_all(doc):
    """Recompute what ``doc`` needs (:func:`pending`), each object once, in dependency
    order, as ``doc.recompute()`` does, but so that each CAM operation's logged errors are
    its own (:func:`cam_errors`). Returns the objects that failed."""
    return [o for o in pending(doc) if not recompute_one(o)]


def recompute_with_progress(doc, title, todo=None):
    """Recompute the objects of ``doc`` that need it (``todo``, default :func:`pending`), each
    once, in dependency order, advancing FreeCAD's progress indicator between them (Esc
    raises :class:`surfcomp.errors.Cancelled` there).

    This runs in this process: the GUI paints only between two objects. The GUI's Replace
    and Restore compute the CAM operations in a child process instead
    (:mod:`surfcomp.app.recompute`).

    Returns the names of the objects recomputed. On Cancelled the objects already
    recomputed keep their new results: the caller undoes its change and recomputes.
    """
    todo = pending(doc) if todo is None else list(todo)
    done = []
    with freecad_progress(title) as progress:
        progress(0.0, title)
        for k, o in enumerate(todo):
            recompute_one(o)
            done.append(o.Name)
            progress((k + 1.0) / max(len(todo), 1), o.Label)
    return done
