# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_filter.py: the filter task panel (live map on every change, RMS
# figures, weights that set the mask size, a bad mask shown without a traceback), Report and
# its HTML, the Mirror command with its stock dialog.
doc = FreeCAD.newDocument("Filter")
nominal, meas = load_example(doc)
comp = make_map(doc, nominal, meas)
vobj = comp.ViewObject
scene = vobj.Proxy.scene
view = view_top()


def colours():
    n = scene.surface_colors.rgb.getNum()
    return np.array([list(scene.surface_colors.rgb[i]) for i in range(0, n, 7)])


Gui.Selection.addSelection(doc.Name, comp.Name)
RESULTS["filter_active"] = active(commands.Filter)
det_before = list(comp.Determined)
Gui.runCommand("SurfComp_Filter")
Gui.updateGui()
RESULTS["filter_dialog_open"] = bool(Gui.Control.activeDialog())
panel = panels.FilterPanel.instance
RESULTS["figures_initial"] = panel.figures.text()
# what the user sees of the options: the panel's widgets and the property view's tooltips
RESULTS["panel_options"] = {
    "mask_range": [panel.mask.minimum(), panel.mask.maximum()],
    "kind_items": [panel.kind.itemText(i) for i in range(panel.kind.count())],
    "edge_items": [panel.edge.itemText(i) for i in range(panel.edge.count())],
    "tooltips": {"mask_size": panel.mask.toolTip(), "weights": panel.weights.toolTip(),
                 "mask_kind": panel.kind.toolTip(), "edge": panel.edge.toolTip()},
    "labels": {name: panel.form.layout().labelForField(field).text()
               for name, field in (("mask_size", panel.mask), ("weights", panel.weights),
                                   ("mask_kind", panel.kind), ("edge", panel.edge))}}
RESULTS["property_options"] = {
    name: [comp.getDocumentationOfProperty(name),
           comp.getEnumerationsOfProperty(name) if name in ("Method", "MaskKind", "Edge",
                                                            "Layout") else None]
    for name in ("Method", "MaskSize", "Weights", "MaskKind", "Sigma", "Edge", "Refine",
                 "Layout", "Smoothing", "TipRadius", "MaxOffset", "StockOk")}

# the stale map: mask 5 -> 11 changed the numbers but not the picture
shot_5 = shot(view, "filter_mask5")
cols_5 = colours()
panel.mask.setValue(11)          # through the widget: debounced recompute
t0 = time.perf_counter()
while panel.timer.isActive() and time.perf_counter() - t0 < 5:
    QtGui.QApplication.processEvents()
    time.sleep(0.01)
Gui.updateGui()
RESULTS["mask11"] = [comp.MaskSize, float(np.nanmax(np.abs(np.array(comp.Determined) -
                                                           det_before)))]
RESULTS["shots_mask"] = [shot_5, shot(view, "filter_mask11")]
RESULTS["colours_changed_mask"] = float(np.abs(colours() - cols_5).max())
RESULTS["figures_mask11"] = panel.figures.text()

# weights: they set the mask size (the spin box follows and is disabled)
cols_11 = colours()
panel.weights.setText("1 2 1; 2 4 2; 1 2 1")
panel.update()
Gui.updateGui()
RESULTS["weights"] = [panel.mask.value(), panel.mask.isEnabled(), comp.MaskSize,
                      comp.Weights, float(np.abs(colours() - cols_11).max())]
panel.weights.setText("")
panel.update()

# kind and edge handling redraw too
cols = colours()
panel.kind.setCurrentIndex(1)    # gaussian
panel.update()
RESULTS["kind"] = [comp.MaskKind, float(np.abs(colours() - cols).max())]
cols = colours()
panel.edge.setCurrentIndex((panel.edge.currentIndex() + 1) % panel.edge.count())
panel.update()
RESULTS["edge"] = [comp.Edge, float(np.abs(colours() - cols).max())]

# an even mask: the message in the panel, no recompute, no traceback
report_before = report_view_text()
state_before = list(comp.State)
panel.kind.setCurrentIndex(0)
panel.mask.setValue(4)
Gui.updateGui()
ok = panel.update()
RESULTS["filter_invalid"] = [panel.status.text(), ok, panel.accept(), list(comp.State),
                             state_before]
RESULTS["report_view_added"] = report_view_text()[len(report_before):]
panel.reject()
Gui.updateGui()
RESULTS["filter_after_reject"] = [comp.MaskSize, comp.MaskKind,
                                  float(np.nanmax(np.abs(np.array(comp.Determined) -
                                                         det_before)))]
# Cancel leaves nothing to recompute (the object is not marked touched): what a recompute
# would give is what the undo put back
RESULTS["state_after_reject"] = [list(comp.State), doc.mustExecute()]
comp.touch()
doc.recompute()
RESULTS["recomputed_after_reject"] = float(np.nanmax(np.abs(np.array(comp.Determined) -
                                                            det_before)))
Gui.runCommand("SurfComp_Filter")
panel = panels.FilterPanel.instance
panel.mask.setValue(3)
panel.show.setCurrentIndex(1)
panel.accept()
RESULTS["filter_after_accept"] = [comp.MaskSize, vobj.Map, Gui.Control.activeDialog()]
RESULTS["undo_after_filter"] = doc.UndoNames

# -- report ---------------------------------------------------------------------------------
vobj.Map = "deviation"
vobj.AutoRange = False
vobj.RangeMin = -0.02
vobj.RangeMax = 0.02
Gui.Selection.clearSelection()
Gui.Selection.addSelection(doc.Name, comp.Name)
del DIALOGS[:]
Gui.runCommand("SurfComp_Report")
rep = DIALOGS[0] if DIALOGS else None
if rep is not None:
    rep.copy()
    RESULTS["report"] = {"rows": rep.table.rowCount(), "cols": rep.table.columnCount(),
                         "headers": [rep.table.horizontalHeaderItem(j).text()
                                     for j in range(rep.table.columnCount())],
                         "max_neg": rep.table.item(1, 0).text(),
                         "clipboard": QtGui.QApplication.clipboard().text()}
    saved = rep.save_html()
    RESULTS["report_html"] = {"path": saved, "errors": list(ERRORS),
                              "text": open(saved, encoding="utf-8").read() if saved else ""}
RESULTS["statistics"] = comp.Statistics
vobj.AutoRange = True

# -- mirror (stock): the dialog explains the stock; the sign is on the legend ----------------
dlg = panels.StockDialog("Mirror (stock)", 0.1)
dlg.resize(520, 420)
dlg.show()
Gui.updateGui()
RESULTS["stock_dialog"] = {"tooltip": dlg.spin.toolTip(), "suffix": dlg.spin.suffix(),
                           "value": dlg.value(), "png": os.path.join(TMP, "stock.png"),
                           "range": [dlg.spin.minimum(), dlg.spin.maximum()]}
dlg.grab().save(RESULTS["stock_dialog"]["png"])
dlg.close()
Gui.runCommand("SurfComp_Mirror")
RESULTS["mirror"] = [comp.Method, comp.Stock.Value, vobj.Map, list(comp.State)]
res = np.array(comp.Determined) - comp.Stock.Value - np.array(comp.Increment)
RESULTS["mirror_residual"] = [float(np.nanmax(np.abs(res))),
                              float(np.nanmax(np.abs(res + np.array(comp.Random))))]
doc.undo()
doc.recompute()
RESULTS["after_mirror_undo"] = [comp.Method, comp.Stock.Value]
RESULTS["errors_at_end"] = ERRORS[:]
