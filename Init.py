# SPDX-License-Identifier: LGPL-2.1-or-later
# surfcomp: headless registration (FreeCAD executes this file at start-up, also in freecadcmd).
# Document objects import their proxies from surfcomp.app. Before any document opens, the
# names that CAM objects import but this FreeCAD may not have (OpenCamLib as `ocl`, 0.20's
# `PathScripts.PathJob` and its kin on 1.x) are made to resolve on demand; nothing of the
# CAM workbench is imported here.
from surfcomp.app import cam as _surfcomp_cam

_surfcomp_cam.install_aliases()
del _surfcomp_cam
