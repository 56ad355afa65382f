# SPDX-License-Identifier: LGPL-2.1-or-later
"""What surfcomp's Path dressups share: the proxy's base link and deletion, and how a new
dressup takes its base's place in the Job (as Path's own dressups do)."""

import FreeCAD

from ..errors import InputError
from . import cam
from .proxies import Proxy


class DressupProxy(Proxy):
    """A dressup's proxy: ``Base`` is the path it modifies; deleting the dressup puts the
    base back into the Job and shows it again."""

    def __init__(self, obj, base):
        super().__init__(obj)
        obj.Base = base

    def onDelete(self, obj, args):
        if obj.Base:
            job = cam.find_parent_job(obj)
            if job:
                job.Proxy.addOperation(obj.Base, obj)
            if obj.Base.ViewObject:
                obj.Base.ViewObject.Visibility = True
            obj.Base = None
        return True


def check_base(base):
    """Refuse a base that is no Path object."""
    if not base.isDerivedFrom("Path::Feature"):
        raise InputError("%s is not a Path object (expected an operation or a dressup)"
                         % base.Label)


def place(obj, base):
    """Put the new dressup ``obj`` in ``base``'s place in its Job (when there is one) and
    hide the base in the GUI."""
    job = cam.find_parent_job(base)
    if job is not None:
        job.Proxy.addOperation(obj, base, True)
    if FreeCAD.GuiUp and base.ViewObject:
        base.ViewObject.Visibility = False
