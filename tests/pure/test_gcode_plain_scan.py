# SPDX-License-Identifier: LGPL-2.1-or-later
"""The plain lines of a block found in array operations
(:mod:`surfcomp.io.gcode.plain_scan`) are those the full pattern
:data:`surfcomp.io.gcode.plain.PLAIN` matches, with the same numbers, lengths, decimals
and motion codes as its groups give (``float`` of each number, bit for bit), on random
lines mixing plain lines of every spelling with near misses: numbers with two dots, signs
inside, no digit, long digit strings, lower case, other words, blanks and tabs."""

import random
import re

import numpy as np
import pytest

from surfcomp.io.gcode import plain
from surfcomp.io.gcode.plain_scan import scan_block

#: the pattern of every line with its groups (how the lines were read before): a plain
#: line's ten groups, then ``"\n"``; any other line ``""`` ten times, then ``"\n"`` last
_SCAN = re.compile(r"(?:%s(\n)|[^\n]*(\n))" % plain.PLAIN.pattern)


def _reference(contents):
    """Per line: None, or ``(motion, [(value, size, decimals) or None] * 3, feed)``
    from :data:`_SCAN`'s groups."""
    out = []
    for t in _SCAN.findall("\n".join(contents) + "\n"):
        axes = [(float(t[g - 1]), len(t[g - 1]),
                 len(t[g - 1]) - t[g - 1].find(".") - 1 if "." in t[g - 1] else 0)
                if t[g - 1] else None for g in plain.AXIS_GROUPS]
        if t[10] != "\n" or all(a is None for a in axes):
            out.append(None)
            continue
        motion = int(t[0]) if t[0] else -1
        out.append((motion, axes, float(t[8]) if t[8] else None))
    return out


_NUMBERS = ["0", "1", "-1", "+2", "12.5", "-0.0", "-0", ".5", "-.25", "5.", "+.0",
            "123.4567", "-45.000001", "0.1", "0.3", "1.0000000000000002",
            "9007199254740993", "123456789012345", "1234567890123456", "0.1234567890123456789",
            "9" * 40, "1." + "3" * 35, "9" * 400,
            # not numbers of PLAIN
            ".", "-", "+", "1.2.3", "1-2", "--1", "+-1", "-.", "1..", "", "1e5"]


def _word(rng, letter):
    if rng.random() < 0.15:
        return ""
    return letter + rng.choice(_NUMBERS if rng.random() < 0.2
                               else ["%.*f" % (rng.randint(0, 6), rng.uniform(-500, 500))])


def _line(rng):
    r = rng.random()
    if r < 0.05:
        return rng.choice(["(comment)", "M3 S1000", "G2 X1 Y2 I1 J0", "g1 x1", "", "  ",
                           "G1 X1 A2", "G1 X1 (c)", "N10 G1 X1", "G17", "G0", "F100",
                           "G1 X1 X2", "G2X1", "G001 X1", "G1\tX1"])
    words = [rng.choice(["", "G0", "G1", "G00", "G01", "G10", "G2"]) if rng.random() < 0.8
             else ""] + [_word(rng, a) for a in "XYZF"]
    if rng.random() < 0.1:
        words = rng.sample(words, len(words))
    seps = [rng.choice(["", " ", " ", " "]) if rng.random() < 0.97
            else rng.choice(["  ", "\t"]) for _ in words]
    tail = "" if rng.random() < 0.8 else rng.choice([" ", "\t", " \t ", " x"])
    return "".join(s + w for s, w in zip(seps, words)).lstrip(" " if rng.random() < 0.5
                                                                 else "") + tail


@pytest.mark.parametrize("seed", range(6))
def test_scan_matches_the_pattern_and_float(seed):
    rng = random.Random(seed)
    contents = [_line(rng) for _ in range(3000)]
    ref = _reference(contents)
    scan = scan_block(contents)
    assert scan.plain.tolist() == [r is not None for r in ref]
    assert 0.2 * len(contents) < scan.plain.sum() < 0.9 * len(contents)
    checked = 0
    for k, r in enumerate(ref):
        if r is None:
            continue
        motion, axes, feed = r
        assert scan.motion[k] == motion, contents[k]
        for a, got in enumerate(axes):
            assert scan.present[k, a] == (got is not None), contents[k]
            if got is not None:
                value, size, dec = got
                # bit for bit, the sign of a zero included
                assert np.float64(scan.value[k, a]).tobytes() == np.float64(value).tobytes(), \
                    contents[k]
                assert (scan.size[k, a], scan.decimals[k, a]) == (size, dec), contents[k]
                checked += 1
        assert scan.feed_ok[k] == (feed is None or np.isfinite(feed)), contents[k]
        # the groups a writer takes for a line it rebuilds are the pattern's
        assert plain.plain_groups(contents[k]) == tuple(
            _SCAN.match(contents[k] + "\n").groups("")[:10])
    assert checked > 1000


def test_numbers_near_the_fast_path_limit_are_exact():
    rng = np.random.default_rng(4)
    texts = []
    for digits in range(1, 19):
        for _ in range(60):
            d = "".join(map(str, rng.integers(0, 10, digits)))
            cut = int(rng.integers(0, digits + 1))
            texts.append("%s%s.%s" % (rng.choice(["", "-", "+"]), d[:cut], d[cut:])
                         if cut < digits or rng.random() < 0.5 else d)
    contents = ["X" + t for t in texts]
    scan = scan_block(contents)
    ok = [plain.PLAIN.fullmatch(c) is not None for c in contents]
    assert scan.plain.tolist() == ok and all(ok[:100])
    want = np.array([float(t) for t in texts])
    assert scan.value[:, 0].tobytes() == want.tobytes()
