# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement set: the points of one measurement in mm (no FreeCAD, no files).

Every reader of :mod:`surfcomp.io` returns one, :func:`surfcomp.core.compensation.pipeline.prepare`
takes one, and the virtual machining (:mod:`surfcomp.core.simulation.simulate`) builds one in
memory.
"""

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError

_EXPECTED_COMBOS = "expected nominal+normal+deviation or nominal+measured"


@dataclass
class MeasurementSet:
    """Points read from a measurement file; all lengths in mm.

    Attributes
    ----------
    nominal : ndarray, shape (N, 3) or None
        Nominal points (mm).
    measured : ndarray, shape (N, 3) or None
        Measured (actual) points (mm).
    normal : ndarray, shape (N, 3) or None
        Unit normals (direction cosines, Werner 2022 eq. 1), renormalised.
    deviation : ndarray, shape (N,) or None
        Signed deviation along the normal (mm), positive when the measured point lies on
        the side the normal points to: ``(measured - nominal) . normal``.
    row, col : ndarray of int64, shape (N,) or None
        Grid indices, when the file has them.
    ids : list of str or None
        Point names, when the file has them.
    lines : ndarray of int64, shape (N,)
        1-based line of each point in the source (for messages); ``1..N`` when None is
        given.
    source : str
        File path or name used in messages.
    sha256 : str
        Hex SHA-256 of the raw file bytes.
    units : str
        Unit of the file's length columns (``'mm'``, ``'um'``, ``'in'``, ``'cm'``, ``'m'``),
        or ``'mixed'`` when they differ.
    columns : dict
        Role (``'x_nom'``, ..., ``'i'``, ``'dev'``, ``'row'``, ``'col'``, ``'id'``) -> the
        column name as written in the header.
    ignored_columns : list of str
        Header names of the columns not used.
    warnings : list of str
        ``'file:line: ...'`` texts (ignored columns, normal lengths, deviation check).
    separator : str
        ``','``, ``';'``, ``'\\t'`` or ``' '`` (runs of blanks).
    decimal_comma : bool
        The numbers were written with a decimal comma.
    tip_centres : bool
        The measured points are stylus tip centres (LinuxCNC probe logs), not contact
        points: they need the tip radius (``Options.tip_radius``).
    faces : list of str or None
        The reference face each point names (a plain point file's ``face`` column, read
        with the file and stored with the points), or None.
    """

    nominal: np.ndarray = None
    measured: np.ndarray = None
    normal: np.ndarray = None
    deviation: np.ndarray = None
    row: np.ndarray = None
    col: np.ndarray = None
    ids: list = None
    lines: np.ndarray = None
    source: str = "<data>"
    sha256: str = ""
    units: str = "mm"
    columns: dict = field(default_factory=dict)
    ignored_columns: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    separator: str = ","
    decimal_comma: bool = False
    tip_centres: bool = False
    faces: list = None

    def __post_init__(self):
        if self.lines is None:
            n = next((len(a) for a in (self.nominal, self.measured, self.normal, self.deviation)
                      if a is not None), 0)
            self.lines = np.arange(1, n + 1, dtype=np.int64)

    def kind(self):
        """Which accepted combination of columns the set holds.

        Returns
        -------
        str
            ``'nominal+normal+deviation'``, ``'nominal+measured'``,
            ``'nominal+measured+normal'`` or ``'all'`` (the deviation given as well);
            for the measured-only sets of :mod:`surfcomp.io.pointfiles` (no nominal)
            ``'measured'`` or ``'measured+normal'``.

        Raises
        ------
        InputError
            For a set built by hand that holds none of these.
        """
        if self.nominal is None:
            if self.measured is not None and self.deviation is None:
                return "measured" if self.normal is None else "measured+normal"
        else:
            if self.measured is None:
                if self.normal is not None and self.deviation is not None:
                    return "nominal+normal+deviation"
            elif self.normal is None:
                return "nominal+measured"
            elif self.deviation is not None and "dev" in self.columns:
                return "all"
            else:
                return "nominal+measured+normal"
        raise InputError("the measurement set holds no accepted combination of nominal, "
                         "measured, normal and deviation (%s)" % _EXPECTED_COMBOS, file=self.source)

    def __len__(self):
        return len(self.lines)
