# SPDX-License-Identifier: LGPL-2.1-or-later
"""The scan of a block over its bytes (:mod:`surfcomp.io.gcode.plain_bytes_scan`) and the
pattern's scan (``_scan_pattern``, which reads the blocks with other characters than
ASCII) give the same :class:`BlockScan` on the cases at their edges: a run at the block's
start, numbers longer than the per-place reading, blanks before the first word, tabs; and
a block with a character beyond ASCII goes to the pattern (whose ``\\d`` also takes other
digits). The line lengths a writer takes from a stretch's newlines are the lines'."""

import numpy as np

from surfcomp.io.gcode import plain_scan
from surfcomp.io.gcode.plain_bytes import _line_lengths
from surfcomp.io.gcode.plain_bytes_scan import _LONG

_FIELDS = ("plain", "motion", "present", "size", "decimals", "feed_ok")

_LINES = [
    "1.5 X2",                   # a run at the very start of the block: no word
    "X1", " X1", "  X1", "  Y1", "   Y1", "G1  X1", "G1  Y1", "G1 X1  Z2", "X1   F3",
    "G0X1Y2Z3F4", "G01 X1\t", "G01 X1 \t ", "G1\tX1", "X1\tY2", "G1 X1 Y2 Z3 F",
    "G1 X" + "7" * (_LONG + 5), "G1 X-" + "1" * _LONG + "." + "2" * 9,
    "X" + "1." * (_LONG // 2 + 3), "X" + "-" * (_LONG + 2), "F" + "9" * 400 + " X1",
    "X1 F" + "9" * 400, "X1 F" + "9" * 400 + ".5", "X" + "9" * 400,
    "X123456789012345", "X1234567890123456", "X-.1234567890123456789", "X+.0", "X-0",
    "G00 Z.5", "G10 X1", "G011 X1", "G X1", "X1 G1", "Y1 X2", "X1 X2", "GX1",
    "", " ", "\t", "G1", "F100", "x1", "G1 X1 (c)", "M3 S1000", "G1 X1 A2",
]


def _assert_same(got, want, text):
    """The same plain lines, and the same fields on them (only those are meaningful)."""
    np.testing.assert_array_equal(got.plain, want.plain)
    p = want.plain
    for f in _FIELDS[1:]:
        np.testing.assert_array_equal(getattr(got, f)[p], getattr(want, f)[p], err_msg=f)
    # the numbers of plain lines, bit for bit (NaN where a word is absent)
    assert got.value[p].tobytes() == want.value[p].tobytes(), text


def test_bytes_scan_equals_the_pattern_on_edge_lines():
    text = "\n".join(_LINES) + "\n"
    got = plain_scan.scan_block(_LINES)
    want = plain_scan._scan_pattern(text, len(_LINES))
    _assert_same(got, want, text)
    # the cases are real: some of each kind
    assert got.plain[_LINES.index(" X1")] and not got.plain[_LINES.index("  X1")]
    assert got.plain[_LINES.index("  Y1")] and not got.plain[_LINES.index("   Y1")]
    assert got.plain[_LINES.index("G1  Y1")] and not got.plain[_LINES.index("G1  X1")]
    assert not got.plain[0] and not got.plain[_LINES.index("G1\tX1")]
    long = _LINES.index("G1 X" + "7" * (_LONG + 5))
    assert got.plain[long] and got.value[long, 0] == float("7" * (_LONG + 5))
    assert got.size[long, 0] == _LONG + 5
    assert not got.feed_ok[_LINES.index("X1 F" + "9" * 400)]
    assert np.isinf(got.value[_LINES.index("X" + "9" * 400), 0])


def test_a_block_beyond_ascii_is_read_by_the_pattern():
    lines = ["G1 X1.5 Y2", "(caf\xe9)", "X\u0663.5", "G1 Z-0.25"]
    got = plain_scan.scan_block(lines)
    assert got.plain.tolist() == [True, False, True, True]
    # the pattern's \d takes the Arabic-Indic three, and float reads it
    assert got.value[2, 0] == 3.5 and got.decimals[2, 0] == 1
    ascii_lines = [lines[0], lines[3]]
    _assert_same(plain_scan.scan_block(ascii_lines),
                 plain_scan._scan_pattern("\n".join(ascii_lines) + "\n", 2), ascii_lines)


def test_line_lengths_from_the_newlines():
    for contents in ([("G1 X1", "\n"), ("", "\r\n"), ("X2\r", "\n"), ("M2", "")],
                     [("G1 X1", "\r\n"), ("X2", "\n")], [("X1", "")]):
        text = "".join(c + e for c, e in contents)
        buf = np.frombuffer(text.encode("latin-1"), dtype=np.uint8)
        assert _line_lengths(contents, buf).tolist() == [len(c + e) for c, e in contents]
