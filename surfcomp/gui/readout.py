# SPDX-License-Identifier: LGPL-2.1-or-later
"""Point readout on the colour maps: hovering shows the values of the nearest measured
point in the status bar; a click flags that point on the map (``Flags`` of the view,
saved with the document) or removes its flag.

One pair of Coin event callbacks per 3D view. While a map is shown it takes the mouse
first: the events over it are marked handled, so neither FreeCAD's pre-selection of mesh
elements (``Compensation.Face1394``) nor an object drawn over it (a Path tool path) takes
the hover or the click. The values come from :class:`surfcomp.app.reports.PointLocator`.
"""

import FreeCAD
from pivy import coin

from ..core import colormap
from ..errors import SurfcompError
from . import fcgui

translate = FreeCAD.Qt.translate

#: views with callbacks: [(view, [(event type, callback)])]
_VIEWS = []
#: the last readout (for scripts and tests)
LAST = {}


def _known(view):
    return any(v is view for v, _cbs in _VIEWS)


def install(view=None):
    """Add the callbacks to ``view`` (default: the active 3D view), once."""
    view = view or fcgui.active_view()
    if view is None or not hasattr(view, "addEventCallbackPivy") or _known(view):
        return view
    cbs = []
    for typ, cb in ((coin.SoLocation2Event.getClassTypeId(), _on_move),
                    (coin.SoMouseButtonEvent.getClassTypeId(), _on_click)):
        # removal needs what the add returned (FreeCAD wraps the function)
        cbs.append((typ, view.addEventCallbackPivy(typ, cb) or cb))
    _VIEWS.append((view, cbs))
    return view


def uninstall_all():
    """Remove every callback (workbench unloaded, tests)."""
    while _VIEWS:
        view, cbs = _VIEWS.pop()
        for typ, cb in cbs:
            try:
                view.removeEventCallbackPivy(typ, cb)
            except (RuntimeError, AttributeError):
                pass    # the view was closed


def map_under(view, position):
    """``(view provider proxy, info dict)`` of the map under ``position`` (pixels, origin
    bottom left, as Coin gives it), or ``(None, None)``."""
    from .viewproviders import ViewProviderCompensation

    position = (int(position[0]), int(position[1]))
    try:
        hits = view.getObjectsInfo(position) or []
    except RuntimeError:
        return None, None
    doc = FreeCAD.ActiveDocument
    # the surface first: a face is hit exactly under the cursor, the markers (GL points)
    # within the pick radius, so at a coarse zoom (or a device pixel ratio of 2) the
    # front-most hit is often a neighbouring point's marker
    hits = sorted(hits, key=lambda h: not str(h.get("Component", "")).startswith("Face"))
    for hit in hits:
        obj = doc.getObject(hit.get("Object", "")) if doc is not None else None
        vobj = getattr(obj, "ViewObject", None)
        proxy = getattr(vobj, "Proxy", None)
        if not isinstance(proxy, ViewProviderCompensation) or vobj.DisplayMode != "Map" \
                or not vobj.Visibility or proxy.scene.range is None:
            continue
        world = FreeCAD.Vector(hit["x"], hit["y"], hit["z"])
        local = obj.Placement.inverse().multVec(world)
        try:
            info = proxy.locator().at((local.x, local.y, local.z))
        except SurfcompError:
            return None, None
        return proxy, info
    return None, None


def describe(info, unit="um", label=""):
    """The status bar text of a readout."""
    f = colormap.format_value
    x, y, z = info["xyz"]
    return (translate("SurfComp", "%s point %s at (%.3f, %.3f, %.3f) mm: deviation %s, "
                                  "determined %s, random %s, correction %s")
            % (label, info["id"], x, y, z, f(info["deviation"], unit),
               f(info["determined"], unit), f(info["random"], unit),
               f(info["correction"], unit))).strip()


def hover(view, position):
    """Readout at ``position`` into the status bar; True when over a map."""
    proxy, info = map_under(view, position)
    if proxy is None:
        return False
    text = describe(info, proxy.vobj.Unit, proxy.vobj.Object.Label)
    LAST.clear()
    LAST.update(info, text=text)
    fcgui.show_status(text)
    return True


def click(view, position):
    """Flag (or unflag) the point under ``position`` and select its map; True when over
    a map."""
    proxy, info = map_under(view, position)
    if proxy is None:
        return False
    obj = proxy.vobj.Object
    proxy.toggle_flag(info["node"])
    select_later(obj)
    LAST.clear()
    LAST.update(info, text=describe(info, proxy.vobj.Unit, obj.Label), clicked=True)
    return True


def select_later(obj):
    """Select the whole map ``obj``, alone, once the current event is done, and keep it so
    through the rest of the click: FreeCAD's selection node sees a click before this
    module's callbacks and selects what it hit first (a mesh element of the map, a tool
    path or a CAM Job's stock box in front), on the press and again on the release."""
    from . import cover

    cover.hold_selection(obj)


def _view_of(_event_cb):
    return fcgui.active_view()      # events come from the view under the mouse: the active one


def _on_move(event_cb):
    event = event_cb.getEvent()
    view = _view_of(event_cb)
    if view is not None and hover(view, fcgui.event_position(event)):
        event_cb.setHandled()


def _on_click(event_cb):
    event = event_cb.getEvent()
    if event.getButton() != coin.SoMouseButtonEvent.BUTTON1:
        return
    view = _view_of(event_cb)
    if view is None:
        return
    position = fcgui.event_position(event)
    if event.getState() == coin.SoButtonEvent.DOWN:
        if click(view, position):
            event_cb.setHandled()
        else:
            from . import cover

            cover.end_hold()
    else:
        proxy = map_under(view, position)[0]
        if proxy is not None:
            event_cb.setHandled()       # the release too: no selection of what lies below
            select_later(proxy.vobj.Object)
