# SPDX-License-Identifier: LGPL-2.1-or-later
# Shared prologue of the GUI sessions (tests/gui/session_*.py): runs inside `freecad` (see
# harness.py; it provides RESULTS, FreeCAD, FreeCADGui, QtGui, QtCore). Commands run through
# FreeCAD's command mechanism (Gui.runCommand); dialogs are replaced by recorders
# (surfcomp.gui.dialogs is the one place commands ask the user).
import time  # noqa: F401  (for the sessions)

import numpy as np  # noqa: F401  (for the sessions)

Gui = FreeCADGui
ROOT = os.environ["SURFCOMP_ROOT"]
TMP = os.environ["SURFCOMP_TMP"]
NOMINAL = os.path.join(ROOT, "examples", "nominal.step")
MEAS = os.path.join(ROOT, "examples", "measurements.csv")

import surfcomp  # noqa: F401
from surfcomp.core import colormap  # noqa: F401
from surfcomp.gui import (  # noqa: F401
    commands,
    dialogs,
    fcgui,
    mapscene,
    panels,
    prefs,
    preview,
    readout,
)

Gui.activateWorkbench("SurfCompWorkbench")
mw = Gui.getMainWindow()

# -- dialog recorders --------------------------------------------------------------------
ERRORS, PREVIEWS, DIALOGS, INFOS, FILES = [], [], [], [], []
STOCKS = [0.1]
dialogs.show_error = lambda title, message: ERRORS.append([title, message])
dialogs.show_info = lambda title, message: INFOS.append([title, message])
dialogs.ask_open_file = lambda title, filters: FILES.pop(0)
#: the replaced dialogs, for sessions that drive the real one with input events
REAL_DIALOGS = {"ask_stock": dialogs.ask_stock}
# the scripted user confirms the stock (a stock that does not fit the measured mean too)
dialogs.ask_stock = lambda title, value, deviation=None: (STOCKS[0], True)
dialogs.ask_save_file = lambda title, filters, default="": os.path.join(TMP, "report.html")
#: what a dialog does when it is "run": a function(dialog) -> accepted
ON_DIALOG = []


def _run_dialog(dlg):
    DIALOGS.append(dlg)
    if isinstance(dlg, preview.PreviewDialog):
        PREVIEWS.append(dlg.text.toPlainText())
    if ON_DIALOG:
        return ON_DIALOG.pop(0)(dlg)
    return True


dialogs.run_dialog = _run_dialog


def active(cls):
    return bool(cls().IsActive())


def load_example(doc):
    """Load nominal and measurements through the commands; (nominal, measurement)."""
    FILES.append(NOMINAL)
    Gui.runCommand("SurfComp_LoadNominal")
    FILES.append(MEAS)
    Gui.runCommand("SurfComp_ImportMeasurements")
    meas = [o for o in doc.Objects if o.Name.startswith("Measurement")][-1]
    return doc.getObject("Nominal"), meas


def deviations_in_um(path):
    """The example's measurements with the deviation column in um, its name without a unit
    (the coordinates stay in mm); returns the lines of the example."""
    with open(MEAS) as f:
        rows = f.read().splitlines()
    with open(path, "w") as f:
        for line in rows:
            parts = line.split(",")
            if parts[0].startswith("P"):
                parts[7] = "%.1f" % (float(parts[7]) * 1000.0)
            f.write(",".join(parts) + "\n")
    return rows


def make_map(doc, nominal, meas, command="SurfComp_DeviationMap"):
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
    Gui.Selection.addSelection(doc.Name, meas.Name)
    Gui.runCommand(command)
    Gui.updateGui()
    Gui.Selection.clearSelection()
    return [o for o in doc.Objects if o.Name.startswith("Compensation")][-1]


def settle(view, rounds=40, calm=3):
    """Process pending events until the 3D view's size and camera have stayed the same for
    ``calm`` rounds 50 ms apart: Qt6 layouts resize the view over several event loops and
    FreeCAD 1.x animates camera changes, so a pixel projected before they end is not
    where a later screenshot or mouse event finds the point."""
    last, same = None, 0
    for _ in range(rounds):
        Gui.updateGui()
        state = (tuple(view.getSize()), view.getCamera())
        same = same + 1 if state == last else 0
        if same >= calm:
            return
        last = state
        time.sleep(0.05)


def view_top():
    view = Gui.ActiveDocument.ActiveView
    settle(view)
    view.viewTop()
    view.fitAll()
    settle(view)
    return view


def project(view, points):
    """The pixels (origin bottom left, device pixels as ``getSize``) where ``points`` are
    drawn. Coin's own projection, as rendering and picking do it: ``getPointOnScreen`` leaves
    out the camera's widening of a view taller than wide (``ADJUST_CAMERA``), which the
    Qt6 layouts give the 3D view beside the docks at a device pixel ratio of 2."""
    from pivy import coin

    region = view.getViewer().getSoRenderManager().getViewportRegion()
    aspect = region.getViewportAspectRatio()
    size = region.getViewportSizePixels()
    volume = view.getCameraNode().getViewVolume(aspect)
    if aspect < 1.0:
        volume.scale(1.0 / aspect)
    out = []
    for p in points:
        s = volume.projectToScreen(coin.SbVec3f(*map(float, p)))
        out.append([int(round(s[0] * size[0])), int(round(s[1] * size[1]))])
    return out


def shot(view, name):
    Gui.updateGui()
    path = os.path.join(TMP, name + ".png")
    W, H = view.getSize()
    view.saveImage(path, W, H, "White")
    return path


def gl_widget():
    """The active 3D view's OpenGL viewport (where the mouse events go): the viewport of the
    visible 3D viewer (a QGraphicsView) whose size in device pixels is the view's
    (``getSize``). FreeCAD 1.1 also keeps a small visible GL widget on the main window, and
    with a device pixel ratio other than 1 the sizes in device and in Qt pixels differ."""
    W, H = Gui.ActiveDocument.ActiveView.getSize()
    for v in mw.findChildren(QtGui.QGraphicsView):
        w = v.viewport()
        r = w.devicePixelRatioF()
        if v.isVisible() and abs(w.width() * r - W) <= 1 and abs(w.height() * r - H) <= 1:
            return w
    raise RuntimeError("no 3D viewer of %d x %d device pixels" % (W, H))


def mouse(kind, xy, button=None):
    """A real Qt mouse event on the 3D view at ``xy`` (view pixels, origin bottom left, as
    getPointOnScreen gives them)."""
    w = gl_widget()
    view = Gui.ActiveDocument.ActiveView
    W, H = view.getSize()
    ratio = float(W) / w.width()        # the view counts device pixels
    pos = QtCore.QPointF((xy[0] + 0.5) / ratio, (H - 1 - xy[1] + 0.5) / ratio)
    glob = QtCore.QPointF(w.mapToGlobal(pos.toPoint()))
    types = {"move": QtCore.QEvent.MouseMove, "press": QtCore.QEvent.MouseButtonPress,
             "release": QtCore.QEvent.MouseButtonRelease}
    b = QtCore.Qt.LeftButton if button is None else button
    btn = QtCore.Qt.NoButton if kind == "move" else b
    btns = QtCore.Qt.NoButton if kind in ("move", "release") else b
    # pending events first (a redraw, the viewport's last resize): on FreeCAD 1.1 / Qt6 an
    # event sent before them reached Coin's callbacks in some runs and not in others
    Gui.updateGui()
    ev = QtGui.QMouseEvent(types[kind], pos, glob, btn, btns, QtCore.Qt.NoModifier)
    QtGui.QApplication.sendEvent(w, ev)
    Gui.updateGui()


def selection():
    """``[[object name, [sub-element names]]]`` as the click made it: unresolved
    (``resolve=0``, there since 0.19). Resolving (the default) checks the names against the
    object's shape: FreeCAD 1.x drops those the shape lacks, such as a map mesh's
    ``Vertex-1635``, which would make an element pick look like a whole-object one."""
    return [[s.ObjectName, list(s.SubElementNames)] for s in Gui.Selection.getSelectionEx("", 0)]


def legend_entries():
    """The legend panel's entries after pending events: ``{object label: LegendEntry}``."""
    from surfcomp.gui import legend

    Gui.updateGui()
    d = legend.dock(create=False)
    if d is None or not d.isVisible():
        return {}
    return {e.name: e for e in d.widget().entries}


def legend_shot(label, name):
    """The legend of the map ``label`` as an image: ``{"png", "bar": [left, top, width,
    height] in image pixels, "texts", "title"}`` (None when the panel does not show it)."""
    e = legend_entries().get(label)
    if e is None:
        return None
    pix = e.grab()
    ratio = float(pix.width()) / max(e.width(), 1)
    path = os.path.join(TMP, name + ".png")
    pix.save(path)
    r = e.bar_rect()
    return {"png": path, "bar": [r.left() * ratio, r.top() * ratio, r.width() * ratio,
                                 r.height() * ratio], "texts": e.texts(),
            "size": [e.width(), e.height()], "visible": e.isVisible()}


# -- real input events on widgets ------------------------------------------------------
def click(widget, pos=None, modifiers=None):
    """A real left click at ``pos`` (QPointF) in ``widget``, by default in its middle, with
    keyboard ``modifiers`` (Ctrl adds to the selection)."""
    Gui.updateGui()
    if pos is None:
        pos = QtCore.QPointF(widget.width() / 2.0, widget.height() / 2.0)
    mods = QtCore.Qt.NoModifier if modifiers is None else modifiers
    glob = QtCore.QPointF(widget.mapToGlobal(pos.toPoint()))
    for kind, buttons in ((QtCore.QEvent.MouseButtonPress, QtCore.Qt.LeftButton),
                          (QtCore.QEvent.MouseButtonRelease, QtCore.Qt.NoButton)):
        ev = QtGui.QMouseEvent(kind, pos, glob, QtCore.Qt.LeftButton, buttons, mods)
        QtGui.QApplication.sendEvent(widget, ev)
    Gui.updateGui()


def wait_for_actions():
    """FreeCAD enables and disables the commands' actions on a timer: let it run."""
    for _ in range(12):
        Gui.updateGui()
        time.sleep(0.05)


def tree():
    """The visible model tree."""
    trees = [t for t in mw.findChildren(QtGui.QTreeWidget) if t.isVisible()]
    return max(trees, key=lambda t: t.topLevelItemCount() and t.width())


def click_tree(label, modifiers=None):
    """A real left click on the tree item ``label`` (its document expanded first); the
    selected objects' names after it."""
    t = tree()
    # FreeCAD's tree adds a new object's item, and lays the items out, on timers of its own:
    # the item is waited for, and its place until it stays put (up to 5 s each), so that a
    # loaded machine's late layout does not move the item from under the click
    item = None
    for _ in range(50):
        t.expandAll()
        Gui.updateGui()
        items = t.findItems(label, QtCore.Qt.MatchExactly | QtCore.Qt.MatchRecursive, 0)
        if items:
            item = items[0]
            break
        time.sleep(0.1)
    if item is None:
        raise AssertionError("no tree item labelled %r" % label)
    t.scrollToItem(item)
    r = None
    for _ in range(50):
        Gui.updateGui()
        here = t.visualItemRect(item)
        if here == r:
            break
        r = here
        time.sleep(0.05)
    click(t.viewport(), QtCore.QPointF(r.left() + min(40, r.width() / 2.0), r.center().y()),
          modifiers)
    wait_for_actions()
    return [o.Name for o in Gui.Selection.getSelection()]


def key(widget, code, text="", modifiers=None):
    """A real key press and release on ``widget``."""
    mods = QtCore.Qt.NoModifier if modifiers is None else modifiers
    for kind in (QtCore.QEvent.KeyPress, QtCore.QEvent.KeyRelease):
        QtGui.QApplication.sendEvent(widget, QtGui.QKeyEvent(kind, code, mods, text))
    Gui.updateGui()


def type_value(spin, text):
    """Select the spin box's text (Ctrl+A) and type ``text`` key by key."""
    spin.setFocus()
    key(spin, QtCore.Qt.Key_A, "a", QtCore.Qt.ControlModifier)
    point = spin.locale().decimalPoint()
    point = point if isinstance(point, str) else chr(point)
    for ch in text:
        if ch == ".":
            key(spin, QtCore.Qt.Key_Period if point == "." else QtCore.Qt.Key_Comma, point)
        else:
            key(spin, getattr(QtCore.Qt, "Key_" + ch), ch)


# -- the toolbar, with real clicks ------------------------------------------------------
def button(command):
    """The toolbar button of ``command`` (a QToolButton); FreeCAD's Undo button (a drop-down
    of the undo steps) has no object name: found by its text."""
    for bar in mw.findChildren(QtGui.QToolBar):
        for action in bar.actions():
            if action.objectName() == command or (command == "Std_Undo" and not
                                                  action.objectName() and
                                                  action.text().replace("&", "") == "Undo"):
                w = bar.widgetForAction(action)
                if w is not None and w.isVisible():
                    return action, w
    raise RuntimeError("no toolbar button for %s" % command)


def press(command):
    """A real click on the command's toolbar button; whether it was enabled."""
    action, w = button(command)
    enabled = action.isEnabled()
    click(w)
    wait_for_actions()
    return enabled
