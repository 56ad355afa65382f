# SPDX-License-Identifier: LGPL-2.1-or-later
"""The HTML report's figures (surfcomp.io.html_figures): one MapPainter reusing its figures
over maps of every kind, and one HistPainter over histograms of different ranges and sizes,
draw each figure pixel for pixel as a figure of its own."""

import base64
import io

import numpy as np
from PIL import Image

from surfcomp.io.html_figures import DPI, HistPainter, MapPainter, png


def _pixels(b64):
    img = Image.open(io.BytesIO(base64.b64decode(b64)))
    return img.mode, np.asarray(img, dtype=int)


def _maps():
    """Maps of each kind, differing in extent, aspect and value range, kinds interleaved."""
    rng = np.random.default_rng(4)

    def grid(nx, ny, sx, sy, x0=0.0, amp=20.0):
        X, Y = np.meshgrid(np.linspace(x0, x0 + sx, nx), np.linspace(0, sy, ny), indexing="ij")
        return X, Y, amp * np.sin(X / (sx / 3)) * np.cos(Y / (sy / 2))

    X, Y, V = grid(9, 7, 30, 30)
    V[2, 3] = np.nan
    x, y = rng.uniform(-1200, -1100, 40), rng.uniform(0, 300, 40)
    nan_grid = np.full((8, 6), np.nan)
    style = {"scheme": "rainbow", "range": (-0.01, 0.01)}
    return [(*grid(11, 11, 30, 30), None), (*grid(30, 6, 200, 20), None),
            (x, y, rng.normal(0, 20, 40), None), (X, Y, V, None),
            (nan_grid, nan_grid, rng.normal(0, 5, (8, 6)), None),
            (*grid(5, 25, 10, 120, x0=-1200, amp=6e-5), None),
            (*grid(11, 11, 30, 30), style), (rng.uniform(0, 50, 60), rng.uniform(0, 30, 60),
                                             rng.normal(0, 30, 60), None),
            (nan_grid[:5], nan_grid[:5], rng.normal(0, 50, (5, 6)), None),
            (*grid(12, 12, 40, 30), style)]


def test_a_reused_figure_draws_each_map_as_a_fresh_one():
    painter = MapPainter()
    for i, (x, y, v, style) in enumerate(_maps()):
        title = "map %d [µm]" % i
        mode, reused = _pixels(painter.png(x, y, v, title, style=style))
        _, fresh = _pixels(MapPainter().png(x, y, v, title, style=style))
        assert mode == "RGB"
        assert reused.shape == (round(4.2 * DPI), round(5.2 * DPI), 3)
        assert np.array_equal(reused, fresh), "map %d differs from a fresh figure's" % i
    # one figure per kind and colorbar: grid, points, index, grid with the GUI's range
    assert len(painter._figures) == 4


def test_a_reused_histogram_figure_draws_each_as_a_fresh_one():
    rng = np.random.default_rng(5)
    values = [rng.normal(0, 20, 121), rng.normal(300, 1, 4000), np.array([0.5, 0.7, np.nan]),
              rng.uniform(-1200, -1100, 50), np.full(30, 2.0)]
    painter = HistPainter()
    for i, v in enumerate(values):
        mode, reused = _pixels(png(painter.figure(v, "hist %d" % i, "#4477aa")))
        _, fresh = _pixels(png(HistPainter().figure(v, "hist %d" % i, "#4477aa")))
        assert mode == "RGB"
        assert reused.shape == (round(3.4 * DPI), round(5.0 * DPI), 3)
        assert np.array_equal(reused, fresh), "histogram %d differs from a fresh figure's" % i
