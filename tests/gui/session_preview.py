# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_preview.py: the filter panel's live map after real key presses (XTest
# at the X server, tests/gui/latency.py), from the press to the render that shows the new
# colours; the Filter command from a real click on its toolbar button.
sys.path.insert(0, ROOT)
from tests.gui import latency  # noqa: E402

doc = FreeCAD.newDocument("Preview")
comp = make_map(doc, *load_example(doc))
view = view_top()
app = QtGui.QApplication.instance()


def toolbar_button(command):
    """The toolbar button of a command (its action's widget on the SurfComp toolbar)."""
    bar = [t for t in mw.findChildren(QtGui.QToolBar) if t.objectName() == "SurfComp"][0]
    for action in bar.actions():
        if action.objectName() == command or action.data() == command:
            return bar.widgetForAction(action)
    names = [a.objectName() for a in bar.actions()]
    raise RuntimeError("no %s on the SurfComp toolbar (%s)" % (command, names))


def click(widget):
    """A real left click (press and release) in the middle of ``widget``."""
    pos = QtCore.QPointF(widget.width() / 2.0, widget.height() / 2.0)
    glob = QtCore.QPointF(widget.mapToGlobal(pos.toPoint()))
    for kind in (QtCore.QEvent.MouseButtonPress, QtCore.QEvent.MouseButtonRelease):
        buttons = QtCore.Qt.LeftButton if kind == QtCore.QEvent.MouseButtonPress \
            else QtCore.Qt.NoButton
        ev = QtGui.QMouseEvent(kind, pos, glob, QtCore.Qt.LeftButton, buttons,
                               QtCore.Qt.NoModifier)
        QtGui.QApplication.sendEvent(widget, ev)
        Gui.updateGui()


# -- the Filter command from its toolbar button: the first click opens the panel ----------
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
Gui.updateGui()
button = toolbar_button("SurfComp_Filter")
# FreeCAD enables the commands' buttons on a timer after a selection: a user clicks the
# button once it is enabled
t0 = time.perf_counter()
while not button.isEnabled() and time.perf_counter() - t0 < 5.0:
    Gui.updateGui()
    time.sleep(0.02)
RESULTS["filter_button_enabled"] = button.isEnabled()
click(button)
for _ in range(20):
    Gui.updateGui()
    time.sleep(0.02)
panel = panels.FilterPanel.instance
RESULTS["first_click"] = [panel is not None, bool(Gui.Control.activeDialog()),
                          panel is not None and panel.form.isVisible()]

# -- live preview: key press to repaint -------------------------------------------------------
keys = latency.PanelKeys(app, mw, panel, view, comp.ViewObject.Proxy.scene)
RESULTS["focus"] = [type(app.focusWidget()).__name__, app.activeWindow() is mw]
RESULTS["presses"] = keys.presses(["Up", "Down"] * 4)
RESULTS["mask_after_presses"] = [panel.mask.value(), comp.MaskSize]
# typing custom weights, 80 ms a key: from the last key to the repaint
RESULTS["typing"] = keys.typing("1 2 1; 2 4 2; 1 2 1")
RESULTS["typed"] = [panel.weights.text(), comp.Weights, comp.MaskSize]
RESULTS["load"] = os.getloadavg()[0]
RESULTS["cores"] = os.cpu_count()
keys.close()
panel.reject()
Gui.updateGui()
RESULTS["after_reject"] = [comp.MaskSize, comp.Weights, comp.Preview]
RESULTS["errors_at_end"] = ERRORS[:]
