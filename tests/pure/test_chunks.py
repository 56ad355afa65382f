# SPDX-License-Identifier: LGPL-2.1-or-later
"""Chunked evaluation on several threads gives the serial result bit for bit."""

import os

import numpy as np
import pytest

from surfcomp.core import chunks
from surfcomp.core.compensation.corrected_check import _solve3
from surfcomp.core.surface import bspline


def _surface(n=40, seed=0):
    rng = np.random.default_rng(seed)
    knots = np.r_[[0.0] * 3, np.linspace(0, 1, n - 2), [1.0] * 3]
    return bspline.Surface(rng.random((n, n, 3)), knots, knots, 3, 3, None, (0, 1), (0, 1))


def test_threaded_derivatives_equal_serial(monkeypatch):
    surf = _surface()
    rng = np.random.default_rng(1)
    u, v = rng.random(300_000), rng.random(300_000)   # several chunks
    monkeypatch.setenv("SURFCOMP_THREADS", "1")
    serial = bspline.derivatives(surf, u, v, order=2)
    monkeypatch.setenv("SURFCOMP_THREADS", "3")
    assert chunks.threads() == 3
    threaded = bspline.derivatives(surf, u, v, order=2)
    for a, b in zip(serial, threaded):
        assert np.array_equal(a, b)


def test_an_error_in_one_chunk_is_raised(monkeypatch):
    monkeypatch.setenv("SURFCOMP_THREADS", "2")
    done = np.zeros(10, dtype=bool)

    def job(sl):
        if sl.start == 6:
            raise ValueError("chunk 6")
        done[sl] = True

    with pytest.raises(ValueError, match="chunk 6"):
        chunks.for_chunks(job, 10, 2)
    # every other chunk ran before the error came back; nested calls inside a chunk run
    # serially (no deadlock)
    assert done[[0, 1, 2, 3, 4, 5, 8, 9]].all()
    inner = np.zeros(12)

    def outer(sl):
        def fill(s2):
            inner[s2] = 1.0
        chunks.for_chunks(fill, 12, 3)

    chunks.for_chunks(outer, 4, 1)
    assert inner.sum() == 12


def test_solve3_matches_lu():
    rng = np.random.default_rng(2)
    a, b, c, r = (rng.normal(size=(1000, 3)) for _ in range(4))
    want = np.linalg.solve(np.stack([a, b, c], axis=2), r[..., None])[..., 0]
    np.testing.assert_allclose(np.stack(_solve3(a, b, c, r), axis=1), want, rtol=1e-9,
                               atol=1e-9)


def test_solve3_singular_rows_get_the_least_squares_step():
    """A zero column (the surface's Su on a collapsed edge) gives the minimum-norm
    least-squares step for that row, never NaN; the other rows keep Cramer's result."""
    a = np.array([[1.0, 0, 0], [0, 0, 0]])
    b = np.array([[0.0, 1, 0], [0, 1, 0]])
    c = np.array([[0.0, 0, 1], [0, 0, 1]])
    r = np.array([[1.0, 2, 3], [1, 2, 3]])
    got = np.stack(_solve3(a, b, c, r), axis=1)
    np.testing.assert_allclose(got, [[1, 2, 3], [0, 2, 3]], atol=1e-12)


@pytest.mark.parametrize("value", ["", "0", "-2", "abc", "\u00b2", "2.5"])
def test_unusable_thread_settings_fall_back_to_the_cores(monkeypatch, value):
    monkeypatch.setenv("SURFCOMP_THREADS", value)
    assert chunks.threads() == max(1, min(4, os.cpu_count() or 1))


def test_progress_in_order_and_a_cancel_stops_the_rest(monkeypatch):
    """``done`` reports the slices in order in the caller's thread; when it raises (Esc in
    FreeCAD's progress) the slices not started are cancelled and the error comes back."""
    import threading
    import time

    seen, ran = [], np.zeros(40, dtype=bool)
    caller = threading.get_ident()

    def job(sl):
        time.sleep(0.01)
        ran[sl] = True

    def done(k, count):
        assert threading.get_ident() == caller
        seen.append((k, count))
        if k == 2:
            raise KeyboardInterrupt("cancelled")

    with pytest.raises(KeyboardInterrupt):
        chunks.for_chunks(job, 40, 1, workers=2, done=done)
    assert seen == [(0, 40), (1, 40), (2, 40)]
    assert 3 <= ran.sum() < 40                  # the slices not started never ran
    full = []
    chunks.for_chunks(job, 40, 1, workers=2, done=lambda k, c: full.append(k))
    assert full == list(range(40)) and ran.all()
