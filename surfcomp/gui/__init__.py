# SPDX-License-Identifier: LGPL-2.1-or-later
"""FreeCAD GUI layer of surfcomp: commands, task panels, view providers, colour maps
(imported lazily by InitGui.py)."""
