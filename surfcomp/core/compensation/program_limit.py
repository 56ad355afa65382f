# SPDX-License-Identifier: LGPL-2.1-or-later
"""The most points a moved program is planned at (no FreeCAD).

:func:`surfcomp.core.compensation.program_offset.plan_offset` samples every move near the
face at ``segment_length`` (down to 1 um) and holds the pieces of a whole block, their
moved points and their output lines, at once: about 0.7 kB a piece (measured: 2.3 and
4.6 million pieces of one block, 1.4 and 2.9 GB peak). A long program at a fine segment
length could need more memory than the machine has. :class:`PieceCount` adds up the
pieces of the blocks of one program and refuses, before a block's pieces are made, a
program that would be planned at more than
:data:`surfcomp.core.limits.MAX_SEGMENTS` pieces in all (the limit of the axis-error
route), naming the line where the count passes the limit and the least segment length
the moves near the face read so far would need. The refusal comes before anything is
written (the route writes into a staged file), and before the memory of the block is
spent: a block holds at most the limit's pieces, and a block whose pieces would need more
memory than the machine has (or ``max_memory``) is refused too.
"""

import numpy as np

from ...errors import GCodeError
from .. import budget
from ..axis.moves import _ceil3
from ..limits import MAX_SEGMENTS


class PieceCount:
    """The pieces of one program's blocks, planned in order.

    Parameters
    ----------
    segment_length : float
        The sampling length (mm), for the message.
    limit : int, optional
        Most pieces in all (default :data:`surfcomp.core.limits.MAX_SEGMENTS`).
    source : str, optional
        File name for the message.
    max_memory : int, optional
        Bytes one block's pieces may take (default: the machine's memory,
        :func:`surfcomp.core.budget.machine_memory`).
    """

    def __init__(self, segment_length, limit=MAX_SEGMENTS, source=None, max_memory=None):
        self.segment_length = float(segment_length)
        self.limit = int(limit)
        self.source = source
        self.max_memory = max_memory
        #: pieces planned so far (after the halvings), length (mm) and number of the moves
        #: near the face sampled so far
        self.pieces = 0
        self.length = 0.0
        self.moves = 0

    def admit(self, prog, near, nseg, length):
        """Count the pieces a block's moves ``near`` the face are sampled at (``nseg``
        per move, ``length`` mm each); raise :class:`surfcomp.errors.GCodeError` when the
        program's count would pass the limit."""
        idx = np.flatnonzero(near)
        upto = self.pieces + np.cumsum(nseg[idx])
        self.length += float(length[idx].sum())
        self.moves += idx.size
        if not upto.size:
            return
        if upto[-1] <= self.limit:
            self._memory(prog, int(upto[-1]) - self.pieces)
            self.pieces = int(upto[-1])
            return
        j = idx[int(np.searchsorted(upto, self.limit, side="right"))]
        needed = _ceil3(self.length / max(self.limit - self.moves, 1))
        raise GCodeError("segment_length %g mm: the moves near the face would be planned at "
                         "more than %d pieces (%d by the end of this line's block of the "
                         "program; the count passes the limit at this line), the most one "
                         "moved program "
                         "may hold (memory: about 0.7 kB each); expected a segment_length "
                         "of at least %.3g mm for the %.6g mm of moves near the face read "
                         "so far, or the program in parts"
                         % (self.segment_length, self.limit, int(upto[-1]), needed, self.length),
                         file=self.source, line=int(prog.line[j]) + 1,
                         options=("segment_length",))

    def _memory(self, prog, pieces):
        """Refuse a block whose ``pieces`` would need more memory than allowed."""
        needed = budget.BASE + pieces * budget.PROGRAM_PER_PIECE
        limit, where = self.max_memory, "max_memory"
        if limit is None:
            limit, where = budget.machine_memory(), "the machine's memory"
        if limit is None or needed <= limit:
            return
        raise GCodeError("segment_length %g mm: the %d pieces of the moves near the face in "
                         "this line's block need about %.1f GB of memory, more than %s "
                         "(%.1f GB); expected a larger segment_length or more memory"
                         % (self.segment_length, pieces, needed / 1024 ** 3, where,
                            limit / 1024 ** 3), file=self.source,
                         line=int(prog.line[-1]) + 1, options=("segment_length", "max_memory"))

    def refined(self, added):
        """Count the ``added`` pieces the halvings made."""
        self.pieces += int(added)
