# SPDX-License-Identifier: LGPL-2.1-or-later
"""Virtual machining: the process model, its presets and simulated tables."""
