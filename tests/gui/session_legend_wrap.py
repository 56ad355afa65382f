# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_legend_wrap_gui.py: a deviation map of the example made through the
# commands; its legend then has a long note and a long list of points outside the trimmed
# face (400 points, long ids, one id of 70 characters without a space), refreshed the way
# the map refreshes it; in a 1280x800 main window the legend panel's entry, its text blocks,
# the panel's scroll range, and screenshots of the entry and of the panel scrolled down.
from surfcomp.gui import legend  # noqa: E402

doc = FreeCAD.newDocument("LegendWrap")
nom, meas = load_example(doc)
comp = make_map(doc, nom, meas)
doc.recompute()
Gui.updateGui()
mw.showNormal()
mw.setGeometry(0, 0, 1280, 800)
NAMES = ["ring_A/run_2026-12-03_0815/probe_point_%04d" % k for k in range(400)]
NAMES[3] = "X" * 70
NOTE = ("measured before the mirror correction; includes the fixture's own error and the "
        "probe's lobing, so read it beside the calibration report of the same day")
vp = comp.ViewObject.Proxy
vp.outside_names = lambda: list(NAMES)
vp.scene.legend_data = dict(vp.scene.legend_data, note=NOTE)
legend.refresh()
for _ in range(30):
    Gui.updateGui()
    time.sleep(0.02)
d = legend.dock(create=False)
panel = d.widget()
entry = legend_entries()[comp.Label]
blocks = entry.text_blocks() if hasattr(entry, "text_blocks") else []
RESULTS["entry"] = {"size": [entry.width(), entry.height()], "least": entry.minimumHeight(),
                    "line": entry.fontMetrics().height(),
                    "blocks": [[t, r.x(), r.y(), r.width(), r.height()] for t, _f, r in blocks],
                    "bar": list(entry.bar_rect().getRect()), "texts": entry.texts()}
path = os.path.join(TMP, "legend_entry.png")
pix = entry.grab()
pix.save(path)
RESULTS["entry_shot"] = [path, pix.width() / float(entry.width())]
bar = panel.scroll.verticalScrollBar()
RESULTS["scroll"] = [bar.maximum(), panel.scroll.viewport().height(),
                     panel.inner.height()]
bar.setValue(bar.maximum())
Gui.updateGui()
bottom = entry.mapTo(panel.scroll.viewport(), QtCore.QPoint(0, entry.height())).y()
RESULTS["scrolled_bottom"] = [bottom, panel.scroll.viewport().height()]
path = os.path.join(TMP, "legend_panel.png")
d.grab().save(path)
RESULTS["panel_shot"] = path
RESULTS["errors_at_end"] = ERRORS[:]
