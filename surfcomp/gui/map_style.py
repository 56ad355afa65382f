# SPDX-License-Identifier: LGPL-2.1-or-later
"""The style of a colour map from its view properties (group "Colour map"), checked.

A manual range whose RangeMin is not below its RangeMax, a tolerance band whose TolLow lies
above its TolHigh and a WarnBand that is not a fraction between 0 and 1 cannot be drawn as
set: the map is drawn without them (the automatic range, no band, no warning band) and the
legend and the Report view say which setting was left out and why. Before, the first two
were dropped or raised without a word in the legend (a traceback in the Report view and a
legend that kept the previous band), the third was ignored.
"""

import FreeCAD

from ..core import colormap
from .mapscene import MapStyle

translate = FreeCAD.Qt.translate


def _mm(vobj, name):
    return float(getattr(vobj, name).Value)


def style_of(vobj, quantity=None, shared=None, notes=None):
    """The :class:`MapStyle` the view properties describe (``shared``: the common range
    when Shared is on; ``notes``: quantity -> the sign convention under the title). Its
    ``problems`` name the settings left out (module docstring)."""
    def text(value):
        return colormap.format_value(value, vobj.Unit)

    problems = []
    auto = vobj.AutoRange
    vmin = None if auto else _mm(vobj, "RangeMin")
    vmax = None if auto else _mm(vobj, "RangeMax")
    if not auto and not vmax > vmin:
        problems.append(translate("SurfComp", "RangeMin %s is not below RangeMax %s: the "
                                              "automatic range is drawn") % (text(vmin),
                                                                             text(vmax)))
        vmin = vmax = None
    if auto and shared is not None:
        vmin, vmax = shared
    tol = warn = None
    if vobj.TolBand:
        low, high = _mm(vobj, "TolLow"), _mm(vobj, "TolHigh")
        if low > high:
            problems.append(translate("SurfComp", "TolLow %s is above TolHigh %s: no "
                                                  "tolerance band is drawn") % (text(low),
                                                                                text(high)))
        else:
            tol = (low, high)
        band = float(vobj.WarnBand)
        if 0.0 < band < 1.0:
            warn = band
        elif band != 0.0 and tol is not None:
            problems.append(translate("SurfComp", "WarnBand %g is not a fraction between 0 "
                                                  "and 1 (0.8: the outer 20 %% of the tolerance "
                                                  "warn): no warning band is drawn") % band)
    return MapStyle(scheme=vobj.Scheme, vmin=vmin, vmax=vmax, tolerance=tol, warning=warn,
                    unit=vobj.Unit, stepped=bool(vobj.Stepped),
                    out_of_range=vmin is not None and not auto, show_points=vobj.Points,
                    show_labels=vobj.Labels, show_legend=vobj.Legend,
                    note=(notes or {}).get(quantity, ""), problems=tuple(problems))


def report(proxy, style):
    """Say in the Report view, once per change, what ``style`` left out of the map of
    ``proxy`` (a view provider with ``vobj``)."""
    if getattr(proxy, "_problems", ()) == style.problems:
        return
    proxy._problems = style.problems
    for problem in style.problems:
        FreeCAD.Console.PrintWarning("%s: %s\n" % (proxy.vobj.Object.Label, problem))
