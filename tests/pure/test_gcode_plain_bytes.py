# SPDX-License-Identifier: LGPL-2.1-or-later
"""The digits of rewritten numbers made by array arithmetic equal ``'%.*f'``'s."""

import numpy as np

from surfcomp.io.gcode.emitter import _fmt
from surfcomp.io.gcode.plain_bytes import number_bytes
from surfcomp.io.gcode.plain_write import _round_units


def _texts(x, d):
    data, size = number_bytes(_round_units(x, d), d)
    text = data.tobytes().decode("ascii")
    off = np.r_[0, np.cumsum(size)]
    return [text[off[k]:off[k + 1]] for k in range(x.size)]


def test_number_bytes_equal_percent_format():
    rng = np.random.default_rng(7)
    x = np.concatenate([rng.normal(0, 100, 20000), rng.normal(0, 1e-4, 2000),
                        [0.0, -0.0, 99999.99995, 1e5, -1e5, 5e-5, -5e-5, 0.5, 9.99995,
                         -9.99995, 1e10, 0.25, -0.125]])
    for d in (np.full(x.size, 4), rng.integers(1, 8, x.size)):
        want = [_fmt(float(v), int(k), int(k)) for v, k in zip(x, d)]
        assert _texts(x, d) == want
    # ties and the minus sign of a zero, as _fmt writes them
    assert _texts(np.array([-0.00004, 0.00005, 1.00005]), np.full(3, 4)) == [
        "0.0000", "%.4f" % 0.00005, "%.4f" % 1.00005]
    assert number_bytes(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=int))[0].size == 0
