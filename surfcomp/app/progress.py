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
