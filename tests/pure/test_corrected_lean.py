# SPDX-License-Identifier: LGPL-2.1-or-later
"""The lean corrected face: a grid along the parameter lines first gets the nominal's knots
plus one span per grid step (knots on the node lines), kept when it meets the limits
(realised = intended within 0.1 um at the points, the nominal back within 0.1 um from a
zero field, no overshoot over max|intended| + 1 um); otherwise the refined space.
"""

import numpy as np
import pytest

from surfcomp.core.compensation import corrected
from surfcomp.core.compensation.corrected import (
    construct,
    grid_lines,
    meets_limits,
    node_line_knots,
)

from .test_corrected_dense import bicubic

UM = 1e-3


def case(n, noise, seed=2):
    t = np.linspace(0.01, 0.99, n)
    U, V = np.meshgrid(t, t, indexing="ij")
    rng = np.random.default_rng(seed)
    delta = 0.03 * np.sin(3 * U) * np.cos(2 * V) + 0.01 + rng.normal(0, 1, U.shape) * noise
    return U, V, delta, 0.98 / (n - 1)


@pytest.mark.parametrize("noise", [0.0, 0.0015])
def test_example_sized_grid_gets_one_span_per_step(noise):
    """45 x 45 points on the example-like face (interior knots 0.3, 0.55, 0.8): each
    interior knot takes the place of its nearest node line, so 45 interior knots (46
    spans: 44 grid steps and the two border strips) and 49 poles instead of 4 spans per
    step (183)."""
    surf = bicubic()
    U, V, delta, step = case(45, noise)
    built = construct(surf, U, V, delta, 1, step, step, refine=4)
    ch = built.checks
    assert ch.poles_shape == (49, 49)
    assert meets_limits(ch)
    assert ch.max_error_at_points < 0.1 * UM and ch.max_zero_deviation < 0.1 * UM
    assert ch.max_realised <= ch.max_intended + 1 * UM


def test_lean_space_missing_the_limits_falls_back_to_a_finer_one():
    """15 x 15 raw points with 2 um noise: one span per step overshoots between the nodes
    (1.5 um over max|intended|, measured), so the next spaces of the ladder (1.5 and 2
    spans per step) are tried: the first that meets the limits is kept (27 x 27 poles,
    against 123 x 123 for ``refine`` spans per step with at least MIN_SPANS)."""
    surf = bicubic()
    U, V, delta, step = case(15, 0.002)
    lines = grid_lines(U, V)
    smp = corrected._Sampling(surf, 1, step, step, 4, lines)
    lean = corrected._checked(smp, *corrected._match(smp, U, V, delta, 1, corrected.MATCH_TOL,
                                                     8, corrected.GridField, None),
                              surf, U, V, delta, 1, U.shape)
    assert lean.checks.poles_shape[0] <= 15 + 4 and not meets_limits(lean.checks)
    built = construct(surf, U, V, delta, 1, step, step, refine=4)
    assert 15 + 4 < built.checks.poles_shape[0] <= 2 * 14 + 8
    assert meets_limits(built.checks)
    # without the ladder (documents made before it): the refined space
    old = construct(surf, U, V, delta, 1, step, step, refine=4, lean=False)
    assert old.checks.poles_shape[0] >= corrected.MIN_SPANS + 3 and meets_limits(old.checks)


def test_nominal_knot_replaces_its_nearest_node_line():
    own = [0, 0, 0, 0, 0.25, 1, 1, 1, 1]
    lines = np.linspace(0.01, 0.99, 1000)           # 0.25 lies about half a step off a line
    k = node_line_knots(own, 0.0, 1.0, lines)
    # 1000 lines, one replaced by 0.25, two knots in each strip of 10 steps beyond the grid
    assert k.size == 1000 - 1 + 4
    step = lines[1] - lines[0]
    np.testing.assert_allclose(k[:2], [0.01 - 4 * step, 0.01 - step])
    np.testing.assert_allclose(k[-2:], [0.99 + step, 0.99 + 4 * step])
    assert np.min(np.abs(k - 0.25)) > 0.4 * step     # no line left right next to 0.25
    # 0.5 lies halfway between two lines whose gap is a little wider than the median step
    # (rounded coordinates): it still replaces one of them
    lines[500:] += 2e-8
    assert 0.5 < np.min(np.abs(lines - 0.5)) / step < 0.5001
    k = node_line_knots([0, 0, 0, 0, 0.25, 0.5, 1, 1, 1, 1], 0.0, 1.0, lines)
    assert k.size == 1000 - 2 + 4


def test_lines_on_the_border_make_no_empty_span():
    """A grid up to the face's border (parameters rounded to 3.9e-33 off it, as on the pipe
    quarter) gives no knot next to the border; one 1/10 step inside stays."""
    lines = np.linspace(0.0, 1.0, 9)
    lines[0] = 3.9e-33
    k = node_line_knots([0, 0, 1, 1], 0.0, 1.0, lines)
    np.testing.assert_allclose(k, lines[1:-1])
    lines[0] = 0.0125                               # a tenth of the 0.125 step
    assert node_line_knots([0, 0, 1, 1], 0.0, 1.0, lines)[0] == 0.0125


def test_lean_off_builds_refine_spans_per_step():
    """``lean=False`` (documents made before the lean face, job files) skips the lean space:
    4 spans per grid step as before; the option takes true or false only."""
    from surfcomp.core.compensation.pipeline import Options
    from surfcomp.errors import InputError

    surf = bicubic()
    U, V, delta, step = case(45, 0.0)
    built = construct(surf, U, V, delta, 1, step, step, refine=4, lean=False)
    assert built.checks.poles_shape[0] >= 4 * 44 + 3 and meets_limits(built.checks)
    Options(lean=False).validate()
    with pytest.raises(InputError, match="lean 'no': expected true or false"):
        Options(lean="no").validate()
