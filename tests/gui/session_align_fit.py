# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_align_fit_gui.py: the Align measurements panel opened as a user opens
# it (the example's nominal and re-clamped points loaded through the commands, the
# compensation picked in the tree, the menu command), a best fit applied so the result box
# holds the alignment report; then, with the main window at 1600x1200 and at 1280x800,
# where Apply and the result box lie in the task view's visible part (the view not
# scrolled), with a screenshot of the window and of the panel for each.
from surfcomp.app import features  # noqa: E402
from surfcomp.core.measurement import align  # noqa: E402
from surfcomp.gui import align_panel  # noqa: E402
from surfcomp.io.readers import read_any  # noqa: E402

# the example's measured points after re-clamping (0.3 deg about Z, 50 um): a best fit has
# something to report
ms = read_any(MEAS)
moved = os.path.join(TMP, "moved.xyz")
np.savetxt(moved, align.apply(align.work_offset([0.04, -0.03, 0.05], 0.3),
                              ms.nominal + ms.normal * ms.deviation[:, None]),
           fmt="%.10f", header="x y z", comments="")
doc = FreeCAD.newDocument("AlignFit")
FILES.append(NOMINAL)
Gui.runCommand("SurfComp_LoadNominal")
FILES.append(moved)
Gui.runCommand("SurfComp_ImportMeasurements")
nom = doc.getObject("Nominal")
meas = [o for o in doc.Objects if o.Name.startswith("Measurement")][-1]
comp = features.make_compensation(doc, nom, "Face1", meas)
doc.recompute()
Gui.Selection.clearSelection()
RESULTS["picked"] = click_tree(comp.Label)
RESULTS["enabled"] = active(align_panel.AlignMeasurements)
Gui.runCommand("SurfComp_AlignMeasurements")
Gui.updateGui()
panel = align_panel.AlignPanel.instance
panel.method.setFocus()
key(panel.method, QtCore.Qt.Key_Down)
click(panel.apply_button)
RESULTS["applied"] = [panel.method.currentText(), panel.result.toPlainText()]


def scroll_area(widget):
    """The task view's scroll area around ``widget``."""
    area = widget.parentWidget()
    while area is not None and not isinstance(area, QtGui.QScrollArea):
        area = area.parentWidget()
    return area


def visible(widget, area):
    """``widget``'s rectangle in the scroll area's viewport, and the viewport's size."""
    top_left = widget.mapTo(area.viewport(), QtCore.QPoint(0, 0))
    return [top_left.x(), top_left.y(), widget.width(), widget.height(),
            area.viewport().width(), area.viewport().height()]


RESULTS["sizes"] = {}
for width, height in ((1600, 1200), (1280, 800)):
    mw.showNormal()
    mw.setGeometry(0, 0, width, height)
    for _ in range(30):
        Gui.updateGui()
        time.sleep(0.02)
    area = scroll_area(panel.form)
    path = os.path.join(TMP, "align_fit_%dx%d.png" % (width, height))
    mw.grab().save(path)
    panel.form.grab().save(path.replace(".png", "_panel.png"))
    RESULTS["sizes"]["%dx%d" % (width, height)] = {
        "window": [mw.width(), mw.height()], "result": visible(panel.result, area),
        "apply": visible(panel.apply_button, area), "form": [panel.form.width(),
                                                             panel.form.height()],
        "scrolled": [area.verticalScrollBar().value(), area.horizontalScrollBar().value()],
        "shot": path, "ratio": mw.devicePixelRatioF(),
        "options": [panel.options.height(), panel.options.widget().height()],
        "form_least": panel.form.minimumSizeHint().height(),
        "view_scroll": area.verticalScrollBar().maximum()}
RESULTS["closed"] = panel.reject()
RESULTS["errors_at_end"] = ERRORS[:]
