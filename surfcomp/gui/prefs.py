# SPDX-License-Identifier: LGPL-2.1-or-later
"""User preferences of the SurfComp workbench: group, keys, typed getters with defaults.

The preferences page (``resources/ui/preferences.ui``) writes the same keys with
``Gui::Pref*`` widgets: combo boxes store the item *index*, so the choice lists below
must list the items in the order of the .ui file. Core code never reads preferences:
the GUI passes every value as an argument.
"""

import FreeCAD

from ..core.colormap import SCHEMES
from ..core.options import OPTIONS

GROUP = "User parameter:BaseApp/Preferences/Mod/SurfComp"

MASK_SIZE = "DefaultMaskSize"
METHOD = "DefaultMethod"
EDGE = "DefaultEdge"
SCHEME = "ColourScheme"
TOLERANCE_BAND = "ToleranceBand"
TOLERANCE_LOWER = "ToleranceLower"
TOLERANCE_UPPER = "ToleranceUpper"
DISPLAY_UNIT = "DisplayUnit"
FILE_UNITS = "MeasurementUnits"

#: choice lists in the order of the .ui combo boxes
METHOD_CHOICES = OPTIONS["method"].choices
EDGE_CHOICES = OPTIONS["edge"].choices
SCHEME_CHOICES = tuple(SCHEMES)
DISPLAY_UNIT_CHOICES = ("mm", "um")
FILE_UNIT_CHOICES = ("mm", "um", "in")

DEFAULTS = {
    MASK_SIZE: OPTIONS["mask_size"].default,
    METHOD: OPTIONS["method"].default,
    EDGE: OPTIONS["edge"].default,
    SCHEME: "rainbow",
    TOLERANCE_BAND: False,
    TOLERANCE_LOWER: -0.01,
    TOLERANCE_UPPER: 0.01,
    DISPLAY_UNIT: "um",
    FILE_UNITS: "mm",
}


def params():
    """The parameter group (``FreeCAD.ParamGet``)."""
    return FreeCAD.ParamGet(GROUP)


def _choice(key, choices):
    default = DEFAULTS[key]
    k = params().GetInt(key, choices.index(default))
    return choices[k] if 0 <= k < len(choices) else default


def _set_choice(key, choices, value):
    params().SetInt(key, choices.index(value))


def mask_size():
    """Default odd filter mask size (Werner 2022 uses 5)."""
    n = params().GetInt(MASK_SIZE, DEFAULTS[MASK_SIZE])
    return n if n >= 1 and n % 2 == 1 else DEFAULTS[MASK_SIZE]


def method():
    """Default compensation method (one of :data:`METHOD_CHOICES`)."""
    return _choice(METHOD, METHOD_CHOICES)


def edge():
    """Default filter edge handling (one of :data:`EDGE_CHOICES`)."""
    return _choice(EDGE, EDGE_CHOICES)


def scheme():
    """Colour scheme of new maps (one of :data:`SCHEME_CHOICES`)."""
    return _choice(SCHEME, SCHEME_CHOICES)


def tolerance_band():
    """Whether new maps start in tolerance-band mode."""
    return params().GetBool(TOLERANCE_BAND, DEFAULTS[TOLERANCE_BAND])


def tolerance():
    """The tolerance band ``(lower, upper)`` in mm."""
    p = params()
    return (p.GetFloat(TOLERANCE_LOWER, DEFAULTS[TOLERANCE_LOWER]),
            p.GetFloat(TOLERANCE_UPPER, DEFAULTS[TOLERANCE_UPPER]))


def display_unit():
    """Unit of legends, labels and reports: ``'mm'`` or ``'um'``."""
    return _choice(DISPLAY_UNIT, DISPLAY_UNIT_CHOICES)


def file_units():
    """Units of measurement columns without a unit of their own."""
    return _choice(FILE_UNITS, FILE_UNIT_CHOICES)


def set_value(key, value):
    """Store a preference with the type the page's widget uses (tests, scripts)."""
    if key == MASK_SIZE:
        params().SetInt(key, int(value))
    elif key in (TOLERANCE_LOWER, TOLERANCE_UPPER):
        params().SetFloat(key, float(value))
    elif key == TOLERANCE_BAND:
        params().SetBool(key, bool(value))
    else:
        choices = {METHOD: METHOD_CHOICES, EDGE: EDGE_CHOICES, SCHEME: SCHEME_CHOICES,
                   DISPLAY_UNIT: DISPLAY_UNIT_CHOICES, FILE_UNITS: FILE_UNIT_CHOICES}[key]
        _set_choice(key, choices, value)
