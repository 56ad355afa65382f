# SPDX-License-Identifier: LGPL-2.1-or-later
"""Progress reporting and cancellation for long core steps (no FreeCAD).

Core functions that can take long accept ``progress=None``: a callable
``progress(fraction, message)`` with ``fraction`` in [0, 1]. It may raise
:class:`surfcomp.errors.Cancelled` to interrupt; the core function lets it
propagate and has written nothing. The CLI passes a progress line printer, the
GUI FreeCAD's progress indicator.
"""


def report(progress, fraction, message=""):
    """Call ``progress(fraction, message)`` when a callback was given."""
    if progress is not None:
        progress(float(fraction), message)


def sub(progress, start, stop):
    """Return a callback mapping [0, 1] onto [start, stop] of ``progress``."""
    if progress is None:
        return None

    def inner(fraction, message=""):
        progress(start + (stop - start) * float(fraction), message)

    return inner
