# SPDX-License-Identifier: LGPL-2.1-or-later
"""View provider of the "Surface correction" dressup (:mod:`surfcomp.app.dressup_surface`):
FreeCAD draws a ``Path::FeaturePython``'s moves only once a view provider proxy gives it a
display mode. The Add surface correction to operation command gives the new dressup one,
and a document observer gives the dressups of an opened document theirs when it is
activated (dressups made by a script or headless, opened later in the GUI). The base
operation shows under the dressup in the tree, as under CAM's own dressups.
"""

from ..app.dressup_surface import DressupSurfaceCorrection
from . import path_view


def is_surface_dressup(obj):
    return isinstance(getattr(obj, "Proxy", None), DressupSurfaceCorrection)


class ViewProviderSurfaceCorrection(path_view.PathViewProvider):
    """No state: ``dumps``/``loads`` return None. The base operation shows under the
    dressup in the tree."""

    ICON = "SurfComp_AddSurfaceCorrection.svg"

    def claimChildren(self):
        base = getattr(getattr(self, "obj", None), "Base", None)
        return [base] if base is not None else []


def attach(obj):
    """Give a surface correction dressup its view provider and display mode (idempotent);
    True when it got one."""
    return path_view.attach(obj, is_surface_dressup, ViewProviderSurfaceCorrection)


path_view.watch(attach)
