# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route refuses a program whose moves near the face would be planned at
more pieces than the limit, before the block that passes it is sampled
(:class:`surfcomp.core.compensation.program_limit.PieceCount`): the pieces counted are
those the plan makes (every cutting move near the face in ``ceil(length /
segment_length)``), the line named is the one where the count passes the limit, and no
point of the refused block but its move ends is displaced; a block beyond the memory
allowed is refused the same way; the document's dressup counts alike."""

import math

import numpy as np
import pytest

from surfcomp.core import budget
from surfcomp.core.compensation.program_offset import BallOffset
from surfcomp.core.limits import MAX_SEGMENTS
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.errors import GCodeError
from surfcomp.io.gcode import ProgramFile
from surfcomp.io.gcode.offset_stream import offset_commands, offset_stream
from tests.toolpath_checks import drop_cutter

R = 3.0
SURF = werner_surface()


def passes(n, x0=2.0, x1=43.0):
    """A program of ``n`` straight passes across the example face, back and forth, their
    ends on the ball's offset (exact drop cutter): ``(text, [(1-based line, length)] of the
    cutting moves)``."""
    ys = np.linspace(3.0, 42.0, n)
    xs = np.where(np.arange(n) % 2 == 0, x1, x0)
    pts = np.column_stack([np.r_[x0, xs], np.r_[ys[0], ys]])
    z, _ = drop_cutter(SURF, 1, pts, np.full(len(pts), 5.0), R)
    lines = ["G21 G90 G17", "M3 S10000", "G0 Z20", "G0 X%.4f Y%.4f" % tuple(pts[0]),
             "G1 Z%.4f F600" % z[0]]
    cuts = [(len(lines), 20.0 - float("%.4f" % z[0]))]
    prev = np.r_[pts[0], float("%.4f" % z[0])]
    for p, q in zip(pts[1:], z[1:]):
        lines.append("G1 X%.4f Y%.4f Z%.4f" % (p[0], p[1], q))
        here = np.array([float(v) for v in ("%.4f %.4f %.4f" % (p[0], p[1], q)).split()])
        cuts.append((len(lines), float(np.linalg.norm(here - prev))))
        prev = here
    lines += ["G0 Z20", "M2"]
    return "\n".join(lines) + "\n", cuts


def nil(u, v):
    return np.zeros(np.shape(u))


def moved(path, seg, limit, block_lines=None, calls=None, max_memory=None):
    off = BallOffset(SURF, 1, R, nil, 1.0)
    if calls is not None:
        displace = off.displace

        def counted(tips):
            calls.append(len(tips))
            return displace(tips)
        off.displace = counted
    out = []
    po = offset_stream(ProgramFile(str(path)), out.append, off, block_lines=block_lines,
                       segment_length=seg, source="p.ngc", max_segments=limit,
                       max_memory=max_memory)
    return po, "".join(out)


def expected(cuts, seg):
    """Pieces of each cutting move and their running count."""
    n = np.array([max(1, math.ceil(length / seg - 1e-9)) for _line, length in cuts])
    return n, np.cumsum(n)


def test_the_pieces_counted_are_those_planned(tmp_path):
    text, cuts = passes(6)
    path = tmp_path / "p.ngc"
    path.write_text(text)
    n, total = expected(cuts, 0.5)
    po, out = moved(path, 0.5, int(total[-1]))
    # the nil correction moves nothing: the output is the input; the limit itself passes
    assert out == text
    assert po.count.pieces == total[-1] and po.count.moves == len(cuts)
    assert po.count.length == pytest.approx(sum(c[1] for c in cuts), abs=1e-9)
    assert total[-1] > 6 * 41 / 0.5          # six passes of at least 41 mm


@pytest.mark.parametrize("block_lines", [None, 4])
def test_one_piece_more_than_the_limit_is_refused_at_its_line(tmp_path, block_lines):
    text, cuts = passes(6)
    path = tmp_path / "p.ngc"
    path.write_text(text)
    seg = 0.5
    _n, total = expected(cuts, seg)
    limit = int(total[3]) - 1            # passed by the fourth cutting move
    with pytest.raises(GCodeError) as exc:
        moved(path, seg, limit, block_lines)
    err = exc.value
    assert err.line == cuts[3][0] and err.file == "p.ngc"
    assert err.options == ("segment_length",)
    msg = str(err)
    assert "segment_length 0.5 mm" in msg and "more than %d pieces" % limit in msg
    assert "the most one moved program may hold" in msg


def test_the_refused_block_is_not_sampled(tmp_path):
    """Refused on the block's count: only its move ends are displaced, none of the
    pieces (the memory a long program at 1 um would need is never asked for)."""
    text, cuts = passes(300)
    path = tmp_path / "p.ngc"
    path.write_text(text)
    seg = 1e-3
    n, total = expected(cuts, seg)
    assert total[-1] > MAX_SEGMENTS         # 300 passes of 41 mm at 1 um
    calls = []
    with pytest.raises(GCodeError) as exc:
        moved(path, seg, MAX_SEGMENTS, calls=calls)
    k = int(np.searchsorted(total, MAX_SEGMENTS, side="right"))
    assert exc.value.line == cuts[k][0]
    assert calls == [text.count("\nG")]      # the block's move ends, once
    # the least segment length named lets the moves read so far fit within the limit
    least = float(str(exc.value).split("of at least ")[1].split(" mm")[0])
    length = sum(c[1] for c in cuts)
    assert sum(max(1, math.ceil(c[1] / least)) for c in cuts) <= MAX_SEGMENTS
    # (rounded up to three digits)
    assert 0 <= least - length / (MAX_SEGMENTS - len(cuts)) <= 1e-5


def test_a_block_beyond_the_memory_is_refused_before_it_is_sampled(tmp_path):
    """Within the piece limit, but one block's pieces would need more than ``max_memory``
    (:data:`surfcomp.core.budget.PROGRAM_PER_PIECE` a piece): refused on that block, its
    pieces never made; the blocks before it pass."""
    text, cuts = passes(6)
    path = tmp_path / "p.ngc"
    path.write_text(text)
    n, _total = expected(cuts, 0.5)
    # blocks of 4 lines: the first (lines 1-4) has no cutting move, the second (lines 5-8)
    # the plunge and three passes, more than the memory of the first two of them
    limit = budget.BASE + (n[0] + n[1]) * budget.PROGRAM_PER_PIECE
    calls = []
    with pytest.raises(GCodeError) as exc:
        moved(path, 0.5, MAX_SEGMENTS, 4, calls, max_memory=limit)
    err = exc.value
    assert "need about" in str(err) and "more than max_memory" in str(err)
    assert err.line == 8 and err.options == ("segment_length", "max_memory")
    assert calls[-1] == 4                   # the refused block's move ends, nothing after
    _po, out = moved(path, 0.5, MAX_SEGMENTS, 4)
    assert out == text


def test_the_path_dressup_refuses_the_same_way():
    """The document's dressup (:func:`offset_commands`, Path's command list) counts its
    pieces the same way: 300 passes at 1 um refused at the command passing the limit."""
    text, cuts = passes(300)
    commands = []
    for line in text.splitlines():
        words = line.split()
        if words[0] in ("G0", "G1"):
            commands.append((words[0], {w[0]: float(w[1:]) for w in words[1:]}))
    # the text's lines before the first move (G21 G90 G17, M3 S10000) are not commands
    first = next(k for k, line in enumerate(text.splitlines()) if line.startswith("G0"))
    _n, total = expected(cuts, 1e-3)
    k = int(np.searchsorted(total, MAX_SEGMENTS, side="right"))
    with pytest.raises(GCodeError) as exc:
        offset_commands(commands, BallOffset(SURF, 1, R, nil, 1.0), segment_length=1e-3,
                        source="Surface correction")
    assert exc.value.line == cuts[k][0] - first
    assert "more than %d pieces" % MAX_SEGMENTS in str(exc.value)
