# SPDX-License-Identifier: LGPL-2.1-or-later
# surfcomp: headless registration (FreeCAD executes this file at start-up, also in freecadcmd).
# Nothing to register yet: document objects import their proxies from surfcomp.app.
