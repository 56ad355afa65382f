# SPDX-License-Identifier: LGPL-2.1-or-later
"""The choices of the options every front end offers, importable without numpy or scipy.

The command line builds its parser from these (``python3 -m surfcomp --help`` and an
argument error import no numerics); the modules that implement the choices re-export them
(``surfcomp.core.compensation.methods.METHODS``, ``surfcomp.core.compensation.filters.EDGE_MODES``,
``surfcomp.io.readers.FORMATS``).
"""

#: correction methods (:mod:`surfcomp.core.compensation.methods`)
METHODS = ("raw", "filtered", "mirror", "offset")
#: edge handling of the mask filter: 'renormalize' (default, see
#: :mod:`surfcomp.core.compensation.filters`), 'reflect' (the grid mirrored about its border node,
# which
#: is not repeated: numpy.pad's 'reflect', the mode scipy.ndimage calls 'mirror'),
#: 'nearest' (the border node repeated)
EDGE_MODES = ("renormalize", "reflect", "nearest")
#: measurement file formats (:func:`surfcomp.io.readers.read_any`; auto: detected)
MEASUREMENT_FORMATS = ("auto", "table", "xyz", "xyzijk", "probe", "qif")
#: shapes of the filter mask without custom weights
# (:func:`surfcomp.core.compensation.filters.make_mask`)
MASK_KINDS = ("box", "gaussian")
#: how the measured points are arranged: found automatically (a complete grid, else
#: scattered), or forced (:func:`surfcomp.core.compensation.pipeline.prepare`)
LAYOUTS = ("auto", "grid", "scattered")
#: units of values that carry no unit of their own (:mod:`surfcomp.io.measurements`)
UNITS = ("mm", "um", "in")
#: how measured points are aligned to the nominal
#: (:data:`surfcomp.core.measurement.align_report.METHODS`)
ALIGN_METHODS = ("none", "bestfit", "rps")
#: where a measurement plan places its points; the layouts whose count is a number of
#: points; visiting orders; plan file formats (:mod:`surfcomp.core.measurement.planning`,
#: :data:`surfcomp.io.plan_file.PLAN_FORMATS`)
PLAN_LAYOUTS = ("grid", "xy", "adaptive", "uniform")
POINT_LAYOUTS = ("adaptive", "uniform")
PLAN_ORDERS = ("auto", "serpentine", "nearest")
PLAN_FORMATS = ("csv", "xyzijk")
#: probing program dialects and work offsets (:mod:`surfcomp.io.probe_path`)
PROBE_DIALECTS = ("linuxcnc", "fanuc")
WORK_OFFSETS = ("G54", "G55", "G56", "G57", "G58", "G59")
#: fits of the machine-axis error functions (:func:`surfcomp.core.axis.axis_errors.fit_axis_errors`)
AXIS_MODELS = ("linear", "quadratic", "auto")
