# SPDX-License-Identifier: LGPL-2.1-or-later
"""B-spline surfaces: evaluation, fitting, projection of points, trims, parameter grids."""
