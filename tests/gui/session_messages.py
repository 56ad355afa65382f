# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_messages_gui.py: the workbench's task panels and dialogs with their
# longest messages (an import error with its file, line and position; a filter error after a
# short one; the alignment's and the plan's errors naming options; the refused stock; the
# report's note), driven by real key and mouse events; where each message lands and how
# much of it the user sees, with screenshots.
import math  # noqa: E402

from surfcomp.gui import align_panel, plan_panel  # noqa: E402


def task_area(form):
    """The task view's scroll area that shows a task panel's ``form``."""
    w = form
    while w is not None and not isinstance(w, QtGui.QScrollArea):
        w = w.parentWidget()
    return w


def place(widget, area=None):
    """Where ``widget`` shows, in the pixels of the task view's viewport (``area``) or its
    window: ``{top, bottom, height, need, room}``: ``need`` is the height its text needs at
    its width (a label's height for its width; a text box: its lines'), ``room`` the bottom
    of what the user sees (the viewport's or window's height)."""
    Gui.updateGui()
    frame = area.viewport() if area is not None else widget.window()
    top = widget.mapTo(frame, QtCore.QPoint(0, 0)).y()
    if isinstance(widget, QtGui.QLabel):
        need = widget.heightForWidth(widget.width())
    elif isinstance(widget, QtGui.QPlainTextEdit):
        need = text_height(widget)
    else:
        need = widget.height()
    return {"top": top, "bottom": top + widget.height(), "height": widget.height(),
            "need": need, "room": frame.height()}


def text_height(box):
    """Where a text box's last line ends as the box paints it, from the box's top (pixels):
    the lines' geometry moved by the scrolled offset, in the viewport inside the frame."""
    doc = box.document()
    last = box.blockBoundingGeometry(doc.lastBlock()).translated(box.contentOffset())
    return int(math.ceil(box.viewport().geometry().top() + last.bottom()))


def box_state(box):
    """A result box: its text, the scroll range (0: every line shows) and whether its
    scroll bar shows."""
    bar = box.verticalScrollBar()
    return {"text": box.toPlainText(), "scroll": bar.maximum(), "bar": bar.isVisible()}


def shown(dlg):
    dlg.show()
    for _ in range(5):
        Gui.updateGui()
        time.sleep(0.02)


def open_panel(command, cls, *selection):
    """Run ``command`` on ``selection`` (document, object[, face]); its panel and the
    task view's scroll area that shows it."""
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(*selection)
    Gui.runCommand(command)
    Gui.updateGui()
    return cls.instance, task_area(cls.instance.form)


def typed(field, text):
    for ch in text:
        key(field, QtCore.Qt.Key_Space if ch == " " else 0, ch)


def grab(widget, name):
    path = os.path.join(TMP, name + ".png")
    widget.grab().save(path)
    return path


doc = FreeCAD.newDocument("Messages")
nominal, meas = load_example(doc)
comp = make_map(doc, nominal, meas)

# -- the import preview: the coordinates switched to inches (Down keys), every point off the
# face: the error of three lines above the file's text, the dialog as it was shown --------------
preview_state = {}


def to_inches(dlg):
    shown(dlg)
    preview_state["size"] = [dlg.width(), dlg.height()]
    preview_state["ok"] = box_state(dlg.status)
    dlg.coord_unit.setFocus()
    key(dlg.coord_unit, QtCore.Qt.Key_Down)
    key(dlg.coord_unit, QtCore.Qt.Key_Down)
    shown(dlg)
    preview_state["bad"] = box_state(dlg.status)
    preview_state["errors"] = list(dlg.errors)
    preview_state["units"] = dlg.units()
    preview_state["size_after"] = [dlg.width(), dlg.height()]
    preview_state["places"] = [place(w) for w in (dlg.status, dlg.text, dlg.buttons)]
    preview_state["png"] = grab(dlg, "preview_inches")
    click(dlg.buttons.button(QtGui.QDialogButtonBox.Cancel))
    return False


ON_DIALOG.append(to_inches)
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
FILES.append(MEAS)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["preview"] = preview_state

# -- the filter panel: a short error, then a long one typed in the weights field --------------
panel, area = open_panel("SurfComp_Filter", panels.FilterPanel, doc.Name, comp.Name)
panel.weights.setFocus()
typed(panel.weights, "1 2 x")
short = panel.status.text()
key(panel.weights, QtCore.Qt.Key_Backspace)
typed(panel.weights, "1; 2 4 2 4 2 4; 1 2 1 0 0 0 0; 3 3 3 3 3 3 3 3 3; 7 7")
for _ in range(10):
    Gui.updateGui()
    time.sleep(0.02)
RESULTS["filter"] = {"short": short, "long": panel.status.text(),
                     "places": [place(w, area) for w in (panel.figures, panel.status)],
                     "png": grab(area, "filter_long")}
panel.reject()
Gui.updateGui()

# -- the alignment panel: 3-2-1 on a measurement of deviations, refused in the panel -----------
ap, area = open_panel("SurfComp_AlignMeasurements", align_panel.AlignPanel, doc.Name,
                      comp.Name)
ap.method.setFocus()
while ap.method.currentText() != "rps" and ap.method.currentIndex() < ap.method.count() - 1:
    key(ap.method, QtCore.Qt.Key_Down)
ap.rps.setFocus()
typed(ap.rps, "P1,P2,P3;P4,P5;P6")
click(ap.apply_button)
RESULTS["align"] = {"box": box_state(ap.result), "place": place(ap.result, area),
                    "method": ap.method.currentText(), "png": grab(area, "align_error")}
ap.reject()
Gui.updateGui()

# -- the plan panel: a tip too large for the face ----------------------------------------------
pp, area = open_panel("SurfComp_PlanMeasurement", plan_panel.PlanPanel, doc.Name,
                      nominal.Name, "Face1")
type_value(pp.tip, "60")
click(pp.plan_button)
RESULTS["plan"] = {"box": box_state(pp.result), "place": place(pp.result, area),
                   "png": grab(area, "plan_error")}
pp.reject()
Gui.updateGui()

# -- the stock dialog: 0.3 mm refused on the finished example ----------------------------------
dev = np.asarray(comp.Deviation)
dlg = panels.StockDialog("Mirror (stock)", 0.3, dev[np.isfinite(dev)])
shown(dlg)
click(dlg.buttons.button(QtGui.QDialogButtonBox.Ok))
shown(dlg)
RESULTS["stock"] = {"text": dlg.check_text.text(), "visible": dlg.isVisible(),
                    "places": [place(w) for w in (dlg.check_text, dlg.buttons)],
                    "labels": dlg.drawing.label_places(),
                    "drawing": [dlg.drawing.width(), dlg.drawing.height(),
                                dlg.drawing.fontMetrics().lineSpacing()],
                    "png": grab(dlg, "stock_refused")}
dlg.close()

# -- the report of a mirror compensation: the note on the predicted residual -------------------
comp.Method = "mirror"
comp.StockOk = True
doc.recompute()
rep = panels.ReportDialog(comp)
shown(rep)
RESULTS["report"] = {"text": rep.assumes.text(),
                     "places": [place(w) for w in (rep.table, rep.assumes)],
                     "png": grab(rep, "report_mirror")}
rep.close()
