# SPDX-License-Identifier: LGPL-2.1-or-later
"""The column names of a measurement table (no FreeCAD): every accepted spelling of each
role (nominal, measured, normal, deviation ...), the groups of roles that come together,
and the names refused with a hint; :mod:`surfcomp.io.measurements` reads the tables (its
docstring lists the same names)."""

import re

from .units import SUFFIX_BRACKET, split_unit_suffix

_AXES = (("x", "a", "alpha", "i"), ("y", "b", "beta", "j"), ("z", "c", "gamma", "k"))


def _build_aliases():
    nominal, measured, normal = {}, {}, {}
    for x, a, greek, ijk in _AXES:
        nominal[x + "_nom"] = [f % x for f in ("%s_nom", "nom_%s", "%s_nominal", "nominal_%s",
                                                "%snom", "nom%s", "%sn")]
        measured[x + "_meas"] = [f % x for f in (
            "%s_meas", "meas_%s", "%s_measured", "measured_%s", "%s_mes", "mes_%s", "%s_act",
            "act_%s", "%s_actual", "actual_%s", "%smeas", "meas%s", "%sact", "act%s", "%sm")]
        normal[ijk] = [ijk, "n" + x, "n_" + x, "normal_" + x, "cos" + x, "cos_" + x,
                       "cos" + a, "cos_" + a, "cos" + greek, "cos_" + greek]
    return {**nominal, **measured, **normal,
            "dev": ["dev", "deviation", "d", "t", "error", "err"],
            "row": ["row", "row_index", "row_idx"],
            "col": ["col", "column", "col_index", "col_idx", "column_index"],
            "id": ["id", "name", "point", "point_id", "point_name", "pt", "label"]}


#: role -> accepted (normalised) column names; the module docstring lists the same
ALIASES = _build_aliases()
ROLE_OF = {name: role for role, names in ALIASES.items() for name in names}

#: groups of roles that come together
GROUPS = {
    "nominal": ("x_nom", "y_nom", "z_nom"),
    "measured": ("x_meas", "y_meas", "z_meas"),
    "normal": ("i", "j", "k"),
    "deviation": ("dev",),
    "grid": ("row", "col"),
}
GROUP_TEXT = {
    "nominal": "nominal point (x_nom y_nom z_nom)",
    "measured": "measured point (x_meas y_meas z_meas)",
    "normal": "normal (i j k)",
    "deviation": "deviation (dev)",
}
LENGTH_ROLES = GROUPS["nominal"] + GROUPS["measured"] + GROUPS["deviation"]

_AMBIGUOUS = ("x, y, z alone are ambiguous (nominal or measured?): name the columns "
              "x_nom y_nom z_nom or x_meas y_meas z_meas")
_COMPONENTS = ("dx, dy, dz (deviation components) are not read: give the deviation along the "
               "normal as dev with i j k, or the measured point x_meas y_meas z_meas")
#: normalised names that are not accepted -> why
HINTS = {"x": _AMBIGUOUS, "y": _AMBIGUOUS, "z": _AMBIGUOUS,
          "dx": _COMPONENTS, "dy": _COMPONENTS, "dz": _COMPONENTS}


def norm(name):
    return re.sub(r"[^0-9a-z]+", "_", name.lower()).strip("_")


def role_of(name):
    """(role or None, unit or None, bracket unit not understood or None) of a header name."""
    base, unit = split_unit_suffix(name)
    if unit is not None:
        role = ROLE_OF.get(norm(base))
        if role is not None:
            return role, unit, None
    role = ROLE_OF.get(norm(name))
    if role is not None:
        return role, None, None
    m = SUFFIX_BRACKET.match(name)
    if m and ROLE_OF.get(norm(m.group("base"))):
        return ROLE_OF[norm(m.group("base"))], None, m.group("unit")
    return None, None, None
