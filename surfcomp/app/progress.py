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


def recompute_with_progress(doc, title):
    """Recompute the objects of ``doc`` that need it, one by one in dependency order,
    advancing FreeCAD's progress indicator between them (the GUI stays responsive there
    and Esc raises :class:`surfcomp.errors.Cancelled`); then recompute the rest.

    Returns the names of the objects recomputed. On Cancelled the objects already
    recomputed keep their new results: the caller undoes its change and recomputes.
    """
    order = list(getattr(doc, "TopologicalSortedObjects", doc.Objects))
    todo, names = [], set()
    for o in order:
        if "Touched" in o.State or any(x.Name in names for x in o.OutList):
            todo.append(o)
            names.add(o.Name)
    done = []
    with freecad_progress(title) as progress:
        progress(0.0, title)
        for k, o in enumerate(todo):
            o.recompute()
            done.append(o.Name)
            progress((k + 1.0) / max(len(todo), 1), o.Label)
    doc.recompute()
    return done
