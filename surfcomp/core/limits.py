# SPDX-License-Identifier: LGPL-2.1-or-later
"""The limits and tolerances of the compensation, each under one name (lengths in mm).

Importable without numpy. The modules that apply a limit import it from here (and may
re-export it: ``surfcomp.core.compensation.corrected.ACCEPT_TOL`` is this module's); the option
registry (:mod:`surfcomp.core.options`) takes its domains from here. Words as in the glossary of
``docs/architecture.md``.
"""

# ------------------------------------------------------------------ the nominal face
#: OpenCASCADE's largest B-spline degree (``Geom_BSplineSurface::MaxDegree``)
MAX_DEGREE = 25

# ------------------------------------------------------------------ the corrected face
#: the corrected face must realise the intended correction at the measured points within
#: this, and its zero correction reproduce the nominal within this (0.1 um): a lean or
#: capped knot space is kept when it does, and a face that does not is reported
ACCEPT_TOL = 1e-4
#: ... and move nowhere (on the dense check grid) more than the largest intended
#: correction plus this (1 um); a face that does is reported
OVERSHOOT_TOL = 1e-3
#: below this integral of the correction (mm^3) a volume check gives no relative figure
#: (a nil correction: the difference alone is reported)
NIL_INTEGRAL = 1e-9
#: a corrected face of more poles is refused before it is sampled: twice the 2127 x 2127
#: poles (3.7 GB) a turned 1000 x 1000 grid once needed (docs/benchmarks.md); points in
#: metres read as mm asked for 38137 x 38137 (tens of GiB)
POLE_LIMIT = 9_000_000
#: target of the residual iteration at the measured points (0.02 um)
MATCH_TOL = 2e-5
#: iterations of the residual iteration at most
MATCH_ITERATIONS = 8
#: a scattered layout's corrected face is built from its smoothing fit's spline when the
#: intended corrections are the fit's values at the points within this
SMOOTH_MATCH = 1e-9
#: a corrected face whose normal turns more than this many degrees from the nominal's folds
#: over itself (reported): the correction's slopes tilt it by well under a degree, a loop
#: (a correction beyond the radius of a curl) by 90 to 180
FOLD_ANGLE_DEG = 90.0

# ------------------------------------------------------------------ the measured points
#: a given normal more than this many degrees off the face normal is reported
NORMAL_WARNING_DEG = 5.0
#: a file's nominal point farther than this from the face is not a nominal point of this
#: face (another face, another revision of the model, another frame): refused. A CMM
#: program's nominal points are the CAD face's own, printed to 3 or 4 decimals (at most
#: 0.9 um off it)
NOMINAL_OFF_FACE = 0.01
#: ... and one farther than this is reported: the deviations are taken against the file's
#: nominal points, so they are off by as much
NOMINAL_OFF_FACE_WARNING = 1e-3
#: a measured point farther beside its own nominal point (across the normal) than this
#: share of the distance from that nominal point to the next one lies nearer another
#: nominal point than its own: the rows of the file are not pairs
PAIRING_SHARE = 0.5

# ------------------------------------------------------------------ option domains
#: the largest mask accepted (a window of 201 x 201 grid steps); also the largest
#: Gaussian sigma (grid steps)
MAX_MASK_SIZE = 201
#: the smallest Gaussian sigma (grid steps)
MIN_SIGMA = 1e-3
#: knot spans of the corrected surface per measurement grid step, at most
MAX_REFINE = 16
#: the largest semi-finishing allowance of the mirror method
MAX_STOCK = 10.0
#: the accepted distance of a point from the face: at least, at most
MIN_MAX_OFFSET = 1e-4
MAX_MAX_OFFSET = 100.0
#: the largest stylus ball radius
MAX_TIP_RADIUS = 50.0
#: most probe moves per point a probe log joined to its plan may hold (--touches)
MAX_TOUCHES = 9
#: the most points a measurement plan may have
MAX_PLAN_POINTS = 1_000_000
#: the smoothing length of a scattered layout's fit: at least, at most
MIN_SMOOTHING = 1e-3
MAX_SMOOTHING = 1e4

# ------------------------------------------------------------------ regions of faces
#: the region's correction field radius when no smoothing is given: this share of the
#: shape's diagonal, at least FIELD_SPACINGS point spacings (``compensate --faces`` says so)
FIELD_SHARE = 0.05
FIELD_SPACINGS = 4.0

# ------------------------------------------------------------------ the simulation loop
#: largest measurement grid per direction: 800 x 800 with the default ``between`` = 2 is
#: estimated at 3.7 GB (:mod:`surfcomp.core.budget`; measured 1.6 GB); the
#: former 4000 x 4000 ran out of memory at 6.5 GB (it needs about 80 GB) and would have run
#: for days
MAX_GRID = 800
#: most replicas (parts machined per method; the mirror paper machines 4); each takes
#: seconds to minutes
MAX_REPLICAS = 1000

# ------------------------------------------------------------------ G-code programs
#: shortest accepted segment length (mm): 1 um, finer than any machine's resolution matters
MIN_SEGMENT_LENGTH = 1e-3
#: most points a compensated program may be sampled at. Measured on the 2-core development
#: machine (23 GB): about 0.8 kB of memory per output segment from planning to the written
#: text, so 10 million segments take about 8 GB (bench/bench_memory.py).
MAX_SEGMENTS = 10_000_000
