# SPDX-License-Identifier: LGPL-2.1-or-later
"""Measuring: plans of points, probing reach, alignment of measured points."""
