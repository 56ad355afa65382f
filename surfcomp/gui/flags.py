# SPDX-License-Identifier: LGPL-2.1-or-later
"""Where a flag's text goes on the map (FreeCAD GUI only).

A flag is a dot at a measured point and its text at the end of a leader line. The text is
put in the first of eight directions on the screen whose box stays clear of the max/min
labels (which start at their points and run right) and of the flags placed before it, for
the camera of the 3D view at the time; :func:`watch` lays the flags out again when the
camera moves (rotation, zoom), since the texts keep their size on the screen.
"""

import FreeCAD
from pivy import coin
from PySide import QtCore

#: leader length, width of a character and height of a line of text (pixels)
LEADER_PX = 40
CHAR_PX = 9
LINE_PX = 17
#: leader directions tried in turn (screen x right, y up; scaled by LEADER_PX)
DIRECTIONS = ((-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (0.0, 1.4), (0.0, -1.4),
              (-1.4, 0.0), (1.4, 0.0))
#: milliseconds after the last camera change before the flags are laid out again
SETTLE_MS = 150


class Screen:
    """Coin's projection of the 3D view ``view`` as rendering and picking use it: pixels
    (origin bottom left) of document points, and document vectors of pixel offsets."""

    def __init__(self, view):
        region = view.getViewer().getSoRenderManager().getViewportRegion()
        aspect = region.getViewportAspectRatio()
        size = region.getViewportSizePixels()
        self.width, self.height = float(size[0]), float(size[1])
        cam = view.getCameraNode()
        self.volume = cam.getViewVolume(aspect)
        if aspect < 1.0:
            self.volume.scale(1.0 / aspect)
        rot = cam.orientation.getValue()
        self.right = [float(c) for c in rot.multVec(coin.SbVec3f(1.0, 0.0, 0.0))]
        self.up = [float(c) for c in rot.multVec(coin.SbVec3f(0.0, 1.0, 0.0))]

    def pixel(self, p):
        s = self.volume.projectToScreen(coin.SbVec3f(*map(float, p)))
        return float(s[0]) * self.width, float(s[1]) * self.height

    def offset(self, p, dx, dy):
        """The document vector at ``p`` that moves ``dx``, ``dy`` pixels on the screen."""
        x0, y0 = self.pixel(p)
        x1 = self.pixel([a + b for a, b in zip(p, self.right)])[0]
        y1 = self.pixel([a + b for a, b in zip(p, self.up)])[1]
        sx, sy = (x1 - x0) or 1.0, (y1 - y0) or 1.0      # pixels per mm
        return [dx / sx * r + dy / sy * u for r, u in zip(self.right, self.up)]


def _box(x, y, width, justification):
    left = {"right": x - width, "left": x, "center": x - 0.5 * width}[justification]
    return (left, y - 4.0, left + width, y + LINE_PX)


def _overlap(a, b):
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return w * h if w > 0 and h > 0 else 0.0


def layout(screen, to_world, to_local, flags, labels):
    """The flags' leaders.

    Parameters
    ----------
    screen : Screen
    to_world : callable
        Map point -> document point (the object's placement).
    to_local : callable
        Document vector -> map vector (the placement's rotation undone).
    flags : list of (point, text)
        In the map's coordinates.
    labels : list of (point, text)
        The max/min labels (left-aligned at their points).

    Returns
    -------
    list of (point, text, leader, justification)
        ``leader`` the vector (map coordinates) from the point to the text's anchor;
        ``justification`` 'right', 'left' or 'center'.
    """
    taken = []
    for point, text in labels:
        x, y = screen.pixel(to_world(point))
        taken.append(_box(x, y, CHAR_PX * len(text), "left"))
    out = []
    for point, text in flags:
        world = to_world(point)
        x, y = screen.pixel(world)
        width = CHAR_PX * (len(text) + 1)
        best = None
        for dx, dy in DIRECTIONS:
            just = "right" if dx < 0 else "left" if dx > 0 else "center"
            box = _box(x + dx * LEADER_PX, y + dy * LEADER_PX, width, just)
            cost = sum(_overlap(box, t) for t in taken)
            if best is None or cost < best[0]:
                best = (cost, dx, dy, just, box)
            if cost == 0.0:
                break
        _cost, dx, dy, just, box = best
        taken.append(box)
        vector = screen.offset(world, dx * LEADER_PX, dy * LEADER_PX)
        out.append((point, text, to_local(vector), just))
    return out


class _Watch:
    """A node sensor on a camera: ``callback`` once the camera has settled."""

    def __init__(self, callback, document):
        self.callback = callback
        self.document = document
        self.timer = QtCore.QTimer()
        self.timer.setSingleShot(True)
        self.timer.timeout.connect(callback)
        self.sensor = coin.SoNodeSensor(self._changed, None)
        self.camera = None

    def _changed(self, _data, _sensor):
        self.timer.start(SETTLE_MS)

    def attach(self, camera):
        if self.camera is not camera:
            self.sensor.detach()
            self.sensor.attach(camera)
            self.camera = camera

    def detach(self):
        self.sensor.detach()
        self.camera = None
        self.timer.stop()


#: every watch made, to stop those of a closed document
_WATCHES = []


def watch(holder, view, callback=None, document=""):
    """Call ``callback`` when the camera of ``view`` has moved (``holder`` keeps the
    sensor: an object with a ``_flag_watch`` attribute; ``document`` the name of the
    document it draws); ``view`` None stops watching."""
    w = getattr(holder, "_flag_watch", None)
    if view is None:
        if w is not None:
            w.detach()
        return
    if w is None:
        w = holder._flag_watch = _Watch(callback, document)
        _WATCHES.append(w)
    w.attach(view.getCameraNode())


def forget(document):
    """Stop the watches of the closed ``document``."""
    for w in [w for w in _WATCHES if w.document == document]:
        w.detach()
        _WATCHES.remove(w)


def for_map(proxy, flags):
    """:func:`layout` of ``flags`` ``[(point, text)]`` for the map of the view provider
    ``proxy`` (its ``scene``, ``vobj``, ``draw_flags``) in the active 3D view, laid out
    again when its camera moves."""
    from . import fcgui

    view = fcgui.active_view() if flags else None
    obj = proxy.vobj.Object
    watch(proxy, view, proxy.draw_flags, obj.Document.Name)
    if view is None:
        return [(p, t, (0.0, 0.0, 0.0), "left") for p, t in flags]
    pl = obj.Placement
    back = pl.Rotation.inverted()
    return layout(Screen(view), lambda p: tuple(pl.multVec(FreeCAD.Vector(*map(float, p)))),
                  lambda v: tuple(back.multVec(FreeCAD.Vector(*map(float, v)))),
                  flags, proxy.scene.label_anchors)
