# SPDX-License-Identifier: LGPL-2.1-or-later
"""The ball-end displacement of a nominal face and its corrected surface, for the direct
program route and the surface correction dressup (one place for both).

The correction at a contact point is what the corrected face realises there along the
nominal's normal (:class:`surfcomp.core.compensation.realised_feet.RealisedAt`, from the
projection's feet; Newton starts on the nominal point itself, or from the neighbouring
point's intersection along a path); a trimmed face's boundary
(:attr:`surfcomp.app.nominal.Nominal.boundary`) fades the correction out beyond it
(:class:`surfcomp.core.compensation.program_trim.Trim`).
"""

from ..core.compensation.program_offset import BallOffset
from ..core.compensation.realised_feet import RealisedAt


def offset_of(nominal, corrected, radius, blend):
    """The :class:`surfcomp.core.compensation.program_offset.BallOffset` of ``nominal``
    (:class:`surfcomp.app.nominal.Nominal`) corrected to the surface ``corrected``."""
    surface = nominal.surface
    trim = None
    if not nominal.untrimmed:   # imported here: its KD-tree needs the whole scipy.spatial
        from ..core.compensation.program_trim import Trim

        trim = Trim.of(surface, nominal.boundary)
    return BallOffset(nominal.surface, nominal.outward, radius,
                      RealisedAt(nominal.surface, corrected, nominal.outward), blend, trim=trim)
