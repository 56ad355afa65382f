# SPDX-License-Identifier: LGPL-2.1-or-later
"""FreeCAD's progress indicator as the core's progress callback (Esc -> Cancelled)."""

import types

import pytest

from surfcomp.app.progress import STEPS, FreeCADProgress
from surfcomp.errors import Cancelled


class FakeIndicator:
    def __init__(self, abort_at=None):
        self.calls, self.abort_at = [], abort_at

    def start(self, title, steps):
        self.calls.append(("start", title, steps))

    def next(self, can_abort=False):
        n = sum(1 for c in self.calls if c[0] == "next")
        if self.abort_at is not None and n == self.abort_at:
            raise RuntimeError("User aborted")      # what FreeCAD's sequencer raises
        self.calls.append(("next", can_abort))

    def stop(self):
        self.calls.append(("stop",))


def fake_freecad(indicator):
    return types.SimpleNamespace(Base=types.SimpleNamespace(ProgressIndicator=lambda: indicator))


def test_fractions_become_abortable_steps():
    ind = FakeIndicator()
    p = FreeCADProgress(fake_freecad(ind), "work")
    for f in (0.0, 0.25, 0.25, 0.9, 1.0):
        p(f, "x")
    p.stop()
    nexts = [c for c in ind.calls if c[0] == "next"]
    assert ind.calls[0] == ("start", "work", STEPS) and ind.calls[-1] == ("stop",)
    assert len(nexts) == STEPS and all(c[1] is True for c in nexts)


def test_abort_becomes_cancelled():
    p = FreeCADProgress(fake_freecad(FakeIndicator(abort_at=10)), "work")
    with pytest.raises(Cancelled, match="interrupted"):
        p(0.5)
