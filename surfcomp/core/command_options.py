# SPDX-License-Identifier: LGPL-2.1-or-later
"""The option registry's tables of the commands that have no document object: the
simulation loop (``simulate``) and the machine-axis error file (``simulate --axis-errors``,
``gcode``); importable without numpy.

Records of the same type as the compensation's (:class:`surfcomp.core.options.Option`),
listed in :data:`surfcomp.core.option_tables.TABLES` (``find`` looks them up there). Who
reads them:

- :data:`SIMULATE`: ``simulate``'s loop (:mod:`surfcomp.cli.simulate`: the parser, its
  checks and the values without a preset) and
  :data:`~surfcomp.core.simulation.process_model.DEFAULT_STOCK`; the options in
  :data:`PRESET_SET` are the preset's where not given, so the parser leaves them unset;
- :data:`AXIS_FILE`: how the axis error file is read, for ``simulate`` and ``gcode`` (whose
  flag of the units is ``--units``: :data:`GCODE_AXIS_FILE`).
"""

from dataclasses import replace

from .choices import METHODS, UNITS
from .limits import MAX_GRID, MAX_REPLICAS
from .options import Option


def _table(*options):
    return {o.name: o for o in options}


#: the virtual machining loop of ``simulate`` (lengths in mm)
SIMULATE = _table(
    Option("grid", str, "45x45", None, flag="--grid", metavar="NxM",
           note="Werner 2022, or the preset's",
           help="measurement grid, uniform in the face parameters, at most %d x %d"
                % (MAX_GRID, MAX_GRID)),
    # (the one domain open at its top: a margin of 0.5 leaves nothing to measure)
    Option("margin", float, 0.02, None, flag="--margin", metavar="FRACTION", low=0.0,
           high=0.5, what="a fraction >= 0 and < 0.5",
           help="parameter range left free at each border"),
    Option("between", int, 2, None, flag="--between", metavar="K", low=1,
           note="or the preset's",
           help="the corrected parts are measured on a grid K times denser: its nodes and "
                "the points between them"),
    Option("replicas", int, 4, None, flag="--replicas", metavar="N", low=1,
           high=MAX_REPLICAS, note="as the mirror paper, or the preset's",
           help="parts machined per method, at most %d" % MAX_REPLICAS),
    Option("methods", str, "none,offset,raw,filtered,mirror", None, flag="--methods",
           metavar="LIST",
           help="comma-separated methods: %s" % ", ".join(("none",) + METHODS)),
    Option("stock", float, 0.3, None, flag="--stock", metavar="MM", low=0.0,
           note="or the preset's",
           help="allowance in mm the semi-finishing pass leaves, and the mirror method's "
                "stock"),
    Option("seed", int, 0, None, flag="--seed", metavar="N", low=0, help="random seed"),
)

#: the options of :data:`SIMULATE` a preset sets (the parser's default is None: not given)
PRESET_SET = ("grid", "between", "replicas", "stock")

#: the machine-axis error file (``simulate --axis-errors``, ``gcode --axis-errors``)
AXIS_FILE = _table(
    Option("axis_units", str, "mm", None, flag="--axis-units", choices=UNITS,
           help="units of the axis error file without unit suffixes"),
    Option("max_error", float, 1.0, None, flag="--max-error", metavar="MM",
           note="as for gcode",
           help="largest plausible error in mm in the axis error file: a larger one is "
                "refused as a likely unit mistake"),
    Option("reference", str, "0,0,0", None, flag="--reference", metavar="X,Y,Z",
           help="reference point of the axis error measurements"),
)

#: :data:`AXIS_FILE` as ``gcode`` names and explains it
GCODE_AXIS_FILE = _table(
    replace(AXIS_FILE["axis_units"], name="units", flag="--units",
            help="units of error-file columns without a unit suffix"),
    replace(AXIS_FILE["max_error"], note=None,
            help="largest plausible machine error in mm: a larger value in the error file, "
                 "or a larger predicted error at a programmed point, is refused as a likely "
                 "unit mistake"),
    replace(AXIS_FILE["reference"],
            help="where the other slides stood while one slide was measured, in mm in "
                 "error-file coordinates"),
)
