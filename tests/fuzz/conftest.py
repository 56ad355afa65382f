# SPDX-License-Identifier: LGPL-2.1-or-later
"""Fixtures of the bad-input cases. FreeCAD is imported only by the tests that need it
(the property-based tests of the readers stay pure)."""

import hashlib

import pytest

from .harness import EXAMPLE_STEP, sha256

_SHAPES = {}


@pytest.fixture
def cad_cache(monkeypatch):
    """Read the unchanged example nominal through the CAD child process once per session.

    Every other nominal (damaged STEP files, documents) is read as the product reads it;
    the example's shape is the same for the same bytes, so the cases about measurements,
    options and outputs need not start a child each (about 0.5 s apiece)."""
    from surfcomp.app import fcenv

    fcenv.import_freecad()
    from surfcomp.app import cadread, nominal

    real = nominal.read_cad
    real_prefetch = cadread.prefetch
    example = sha256(EXAMPLE_STEP)

    def digest(path):
        try:
            with open(path, "rb") as fh:
                return hashlib.sha256(fh.read()).hexdigest()
        except OSError:
            return None

    def prefetch(path):         # the command line starts the child early: not for these
        if digest(path) != example or example not in _SHAPES:
            real_prefetch(path)

    def read_cad(path, label="NOMINAL"):
        key = digest(path)
        if key != example:
            return real(path, label)
        if key not in _SHAPES:
            _SHAPES[key] = real(path, label)
        return _SHAPES[key].copy()

    monkeypatch.setattr(nominal, "read_cad", read_cad)
    monkeypatch.setattr(cadread, "prefetch", prefetch)
    return read_cad
