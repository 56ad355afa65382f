# SPDX-License-Identifier: LGPL-2.1-or-later
"""Machine-axis compensation: the 3-axis error model and program moves."""
