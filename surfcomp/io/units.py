# SPDX-License-Identifier: LGPL-2.1-or-later
"""Length units in column names and options (no FreeCAD).

Every value inside surfcomp is in millimetres; files and options may use other
units, which are converted once, on reading.
"""

import re

from ..errors import InputError

#: factor that converts one unit into millimetres
UNIT_FACTORS = {
    "mm": 1.0,
    "um": 1e-3,
    "µm": 1e-3,
    "μm": 1e-3,
    "micron": 1e-3,
    "microns": 1e-3,
    "in": 25.4,
    "inch": 25.4,
    "cm": 10.0,
    "m": 1000.0,
}

SUFFIX_BRACKET = re.compile(r"^(?P<base>.*?)\s*[\[(]\s*(?P<unit>[^\])]+?)\s*[\])]\s*$")
_SUFFIX_UNDERSCORE = re.compile(r"^(?P<base>.+?)_(?P<unit>mm|um|µm|μm|in|inch|cm|micron|microns)$",
                                re.IGNORECASE)


def unit_factor(unit, file=None, line=None, column=None):
    """Return the factor converting ``unit`` to mm.

    Parameters
    ----------
    unit : str
        Unit name (``mm``, ``um``/``µm``, ``in``, ``cm``, ``m``), case-insensitive.

    Raises
    ------
    InputError
        For an unknown unit, naming the accepted ones.
    """
    key = unit.strip().lower()
    if key not in UNIT_FACTORS:
        raise InputError("unknown unit %r (expected one of mm, um, in, cm, m)" % unit,
                         file=file, line=line, column=column)
    return UNIT_FACTORS[key]


def split_unit_suffix(name):
    """Split a column name into its base name and unit suffix.

    ``"dev[um]"`` -> ``("dev", "um")``, ``"x_nom_mm"`` -> ``("x_nom", "mm")``,
    ``"x"`` -> ``("x", None)``. The base is stripped but keeps its case.
    """
    text = name.strip()
    m = SUFFIX_BRACKET.match(text)
    if m and m.group("unit").strip().lower() in UNIT_FACTORS:
        return m.group("base").strip(), m.group("unit").strip().lower()
    m = _SUFFIX_UNDERSCORE.match(text)
    if m:
        return m.group("base"), m.group("unit").lower()
    return text, None
