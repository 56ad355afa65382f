# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_stockunits.py: the import preview's two unit selectors and its check
# of the points against the nominal face, and the Mirror command's stock dialog, driven by
# real key and mouse events on the dialogs' widgets.
from surfcomp.app import features


def shown(dlg):
    dlg.show()
    for _ in range(5):
        Gui.updateGui()
        time.sleep(0.02)


def ok_button(dlg):
    return dlg.buttons.button(QtGui.QDialogButtonBox.Ok)


def accepted(dlg):
    return dlg.result() == QtGui.QDialog.Accepted and not dlg.isVisible()


doc = FreeCAD.newDocument("StockUnits")
nominal, meas = load_example(doc)
RESULTS["example_preview"] = PREVIEWS[-1]

# -- the import preview: deviations in um, coordinates in mm (the file) ----------------
um = os.path.join(TMP, "deviations_in_um.csv")
deviations_in_um(um)
state = {}


def look(dlg):
    """Read as mm; the deviation selector to um (Down key); then the coordinate selector to
    um too: the points fall off the face; OK clicked there; back to mm (Up key), OK."""
    shown(dlg)
    state["mm"] = [dlg.text.toPlainText(), dlg.status.toPlainText(), ok_button(dlg).isEnabled()]
    dlg.unit.setFocus()
    key(dlg.unit, QtCore.Qt.Key_Down)
    state["dev_um"] = [dlg.text.toPlainText(), dlg.status.toPlainText(), ok_button(dlg).isEnabled(),
                       dlg.units(), dlg.deviation_units()]
    dlg.coord_unit.setFocus()
    key(dlg.coord_unit, QtCore.Qt.Key_Down)
    state["both_um"] = [dlg.text.toPlainText(), dlg.status.toPlainText(),
                        ok_button(dlg).isEnabled(), dlg.units(), dlg.deviation_units()]
    state["png"] = os.path.join(TMP, "preview_off_face.png")
    dlg.grab().save(state["png"])
    click(ok_button(dlg))
    state["after_ok_click"] = [dlg.isVisible(), dlg.result()]
    key(dlg.coord_unit, QtCore.Qt.Key_Up)
    state["back"] = [dlg.status.toPlainText(), ok_button(dlg).isEnabled(), dlg.units(),
                     dlg.deviation_units()]
    state["png_ok"] = os.path.join(TMP, "preview_dev_um.png")
    dlg.grab().save(state["png_ok"])
    click(ok_button(dlg))
    return accepted(dlg)


n_before = len(doc.Objects)
ON_DIALOG.append(look)
FILES.append(um)
Gui.runCommand("SurfComp_ImportMeasurements")
RESULTS["preview_units"] = state
m_um = doc.Objects[-1]
RESULTS["um_object"] = [len(doc.Objects) - n_before, m_um.Name, m_um.Units,
                        float(max(map(abs, m_um.Deviation))), float(max(m_um.NominalX))]

# the map of it: no error, no traceback
del ERRORS[:]
comp_um = make_map(doc, nominal, m_um)
RESULTS["um_map"] = [list(comp_um.State), ERRORS[:],
                     float(np.max(np.abs(np.asarray(m_um.Deviation) -
                                         np.asarray(meas.Deviation))))]

# a measurement whose coordinates are in um, made by script (the preview refuses it): the
# map is refused with the message in a dialog and the Report view, without a traceback
report_before = len(report_view_text())
m_bad = features.make_measurement(doc, um, units="um")
names_before = sorted(o.Name for o in doc.Objects)
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, nominal.Name, "Face1")
Gui.Selection.addSelection(doc.Name, m_bad.Name)
Gui.runCommand("SurfComp_DeviationMap")
Gui.updateGui()
RESULTS["bad_map"] = [ERRORS[:], sorted(o.Name for o in doc.Objects) == names_before,
                      report_view_text()[report_before:]]
del ERRORS[:]
Gui.Selection.clearSelection()
doc.removeObject(m_bad.Name)

# -- Mirror: the stock dialog refuses the default 0.1 mm on the finished example ----------------
comp = make_map(doc, nominal, meas)
dialogs.ask_stock = REAL_DIALOGS["ask_stock"]
stock = {}


def refuse_then_confirm(dlg):
    shown(dlg)
    stock["initial"] = [dlg.value(), dlg.check_text.text(), dlg.confirm.isVisible()]
    click(ok_button(dlg))
    stock["refused"] = [dlg.isVisible(), dlg.check_text.text(), dlg.confirm.isVisible(),
                        dlg.confirm.text()]
    stock["png"] = os.path.join(TMP, "stock_refused.png")
    dlg.grab().save(stock["png"])
    click(dlg.confirm)
    return accepted(dlg)


def type_a_fitting_stock(dlg):
    shown(dlg)
    type_value(dlg.spin, "0.02")
    stock["typed"] = [dlg.value(), dlg.check_text.text(), dlg.confirm.isVisible()]
    click(ok_button(dlg))
    return accepted(dlg)


def refuse_then_cancel(dlg):
    shown(dlg)
    type_value(dlg.spin, "0.3")
    click(ok_button(dlg))
    stock["refused_03"] = [dlg.isVisible(), dlg.value(), dlg.check_text.text()]
    type_value(dlg.spin, "0.25")          # a new value withdraws the confirmation
    stock["retyped"] = [dlg.confirm.isVisible()]
    click(dlg.buttons.button(QtGui.QDialogButtonBox.Cancel))
    return accepted(dlg)


for hook, name in ((refuse_then_confirm, "confirmed"), (type_a_fitting_stock, "fitting"),
                   (refuse_then_cancel, "cancelled")):
    ON_DIALOG.append(hook)
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(doc.Name, comp.Name)
    Gui.runCommand("SurfComp_Mirror")
    Gui.updateGui()
    stock[name] = [comp.Method, float(comp.Stock.Value), bool(comp.StockOk),
                   list(comp.State), ERRORS[:],
                   float(np.nanmax(np.abs(np.asarray(comp.Correction) -
                                          (np.asarray(comp.Deviation) - comp.Stock.Value))))]
    if name == "confirmed":
        report = panels.ReportDialog(comp)
        stock["report_assumes"] = report.assumes.text()
        report.close()
    del ERRORS[:]
RESULTS["stock"] = stock
RESULTS["report_view_end"] = report_view_text()
RESULTS["errors_at_end"] = ERRORS[:]
