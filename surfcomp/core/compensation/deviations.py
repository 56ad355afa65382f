# SPDX-License-Identifier: LGPL-2.1-or-later
"""Deviations along the nominal normal and their statistics (no FreeCAD).

Sign convention (as CMM reports and Werner 2022): a positive deviation means the
measured point lies on the side the outward normal points to, i.e. material was
left (undercut); negative means material was removed beyond nominal (overcut).
"""

from dataclasses import asdict, dataclass

import numpy as np


def signed_deviation(nominal, measured, normal):
    """Signed distance of measured points from nominal points along the unit normal.

    Parameters
    ----------
    nominal, measured, normal : array_like, shape (N, 3)
        Points in mm; ``normal`` of unit length (outward).

    Returns
    -------
    ndarray, shape (N,)
        ``d = (measured - nominal) . normal`` in mm.
    """
    nominal = np.asarray(nominal, dtype=float)
    measured = np.asarray(measured, dtype=float)
    normal = np.asarray(normal, dtype=float)
    return np.einsum("...k,...k->...", measured - nominal, normal)


def deviation_components(d, normal):
    """Components of the deviations along X, Y, Z (Werner 2022, eq. 1 and 3).

    ``dx = d cos(alpha), dy = d cos(beta), dz = d cos(gamma)`` where the direction
    cosines are the components of the unit normal.

    Parameters
    ----------
    d : array_like, shape (...,)
        Deviations (raw, eq. 1, or filtered, eq. 3) in mm.
    normal : array_like, shape (..., 3)
        Unit normals (direction cosines).

    Returns
    -------
    ndarray, shape (..., 3)
    """
    return np.asarray(d, dtype=float)[..., None] * np.asarray(normal, dtype=float)


@dataclass(frozen=True)
class Statistics:
    """Summary of a deviation set in the form of the papers' tables (mm).

    ``std`` is the sample standard deviation (ddof=1), as CMM software and the
    papers report it; ``rms`` is the root mean square about zero (the nominal);
    ``profile`` is the ISO 1101 surface profile error for a tolerance zone
    centred on the nominal: the zone width ``2 * max|d|``.

    ``max_negative`` is the largest deviation below the nominal (the most negative value)
    and 0.0 when no value is below it; ``max_positive`` the largest above it, 0.0 when none
    is above. ``min`` and ``max`` are the smallest and largest values whatever their signs
    (an all-positive set: ``max_negative`` 0.0, ``min`` its smallest value). The JSON
    report's keys are these field names.
    """

    count: int
    max_negative: float
    max_positive: float
    mean: float
    std: float
    rms: float
    profile: float
    min: float
    max: float

    def as_dict(self):
        return asdict(self)

    @classmethod
    def from_dict(cls, d):
        """Inverse of :meth:`as_dict`; also reads the dict of a document or report made
        before ``min`` and ``max`` existed, whose ``max_negative`` and ``max_positive``
        were the extremes whatever their signs."""
        d = dict(d)
        if "min" not in d or "max" not in d:
            d["min"], d["max"] = d["max_negative"], d["max_positive"]
            d["max_negative"], d["max_positive"] = min(d["min"], 0.0), max(d["max"], 0.0)
        return cls(**{f: d[f] for f in cls.__dataclass_fields__})

    def rows(self, unit="mm"):
        """Table rows ``(label, value)`` in ``unit`` (``mm`` or ``um``); the value of
        "Max. negative" is None when no value is negative, that of "Max. positive" when none
        is positive (shown as :data:`NONE`, not as a deviation of 0)."""
        f = 1000.0 if unit == "um" else 1.0
        return [("Points", self.count),
                ("Max. negative", self.max_negative * f if self.min < 0 else None),
                ("Max. positive", self.max_positive * f if self.max > 0 else None),
                ("Average value", self.mean * f),
                ("Standard deviation (ddof=1)", self.std * f),
                ("RMS", self.rms * f),
                ("Profile error ISO 1101 (2 max|d|)", self.profile * f)]


def statistics(d):
    """Statistics of deviations as in Werner 2022 Tables 1-5 and the mirror paper Tables 2-4.

    Parameters
    ----------
    d : array_like
        Deviations in mm; NaN entries (unmeasured grid nodes) are ignored.

    Returns
    -------
    Statistics
        ``max_negative`` is the most negative value (0.0 when none is negative),
        ``max_positive`` the most positive (0.0 when none is positive); ``min`` and
        ``max`` the extremes whatever their signs.
    """
    a = np.asarray(d, dtype=float).ravel()
    a = a[np.isfinite(a)]
    if a.size == 0:
        raise ValueError("no finite deviations to summarise")
    std = float(np.std(a, ddof=1)) if a.size > 1 else 0.0
    lo, hi = float(a.min()), float(a.max())
    return Statistics(count=int(a.size), max_negative=min(lo, 0.0), max_positive=max(hi, 0.0),
                      mean=float(a.mean()), std=std, rms=float(np.sqrt(np.mean(a * a))),
                      profile=float(2.0 * np.abs(a).max()), min=lo, max=hi)


def format_table(columns, unit="um", title=None):
    """Format statistics side by side like the papers' tables.

    Parameters
    ----------
    columns : list of (str, Statistics)
        Column header and statistics.
    unit : {'um', 'mm'}

    Returns
    -------
    str
    """
    labels = [r[0] for r in columns[0][1].rows(unit)]
    width = max(len(s) for s in labels) + 2
    colw = max(14, max(len(h) for h, _ in columns) + 2)
    out = []
    if title:
        out.append(title)
    out.append(("Deviations (%s)" % ("µm" if unit == "um" else "mm")).ljust(width)
               + "".join(h.rjust(colw) for h, _ in columns))
    for k, label in enumerate(labels):
        cells = [cell_text(st.rows(unit)[k][1], k, unit).rjust(colw) for _, st in columns]
        out.append(label.ljust(width) + "".join(cells))
    return "\n".join(out)


#: the cell of "Max. negative" when no deviation is negative (and of "Max. positive" when
#: none is positive)
NONE = "none"


def cell_text(value, row, unit="um"):
    """The text of a :meth:`Statistics.rows` value in row ``row`` (row 0: the count)."""
    if value is None:
        return NONE
    if row == 0:
        return "%d" % value
    return ("%.2f" if unit == "um" else "%.4f") % value
