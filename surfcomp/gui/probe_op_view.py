# SPDX-License-Identifier: LGPL-2.1-or-later
"""View provider of the probe operation: FreeCAD draws a ``Path::FeaturePython``'s moves
(rapids red, feeds green) only once a view provider proxy gives it a display mode.

Registered as a creation and restore hook of :mod:`surfcomp.app.features`, and a document
observer gives the operations of an opened document theirs when it is activated (FreeCAD
0.20 may restore the object before its view object), so operations made by the command, by
a script or headless (opened later in the GUI) all get it.
"""

from ..app import features
from ..app.probe_op import is_probe_operation
from . import path_view


class ViewProviderProbeOperation(path_view.PathViewProvider):
    """No state: ``dumps``/``loads`` return None."""

    ICON = "SurfComp_AddProbeOperation.svg"


def attach(obj):
    """Give a probe operation its view provider and display mode (idempotent); True when it
    got one."""
    return path_view.attach(obj, is_probe_operation, ViewProviderProbeOperation)


for _hooks in (features.NEW_OBJECT_HOOKS, features.RESTORED_HOOKS):
    if attach not in _hooks:
        _hooks.append(attach)
path_view.watch(attach)
