# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_map_settings_gui.py: the example's deviation map with colour-map
# settings that cannot be drawn as set, written as the property view writes them (one
# property at a time): a manual range whose RangeMin is not below RangeMax, a WarnBand
# typed as a percentage, a tolerance band whose TolLow lies above TolHigh; then each set
# right again. Per step: the legend's texts, the range and band the map is drawn with, and
# the Report view's new lines; a picture of the legend entry with its red line.
from surfcomp.gui import legend  # noqa: E402, F401

doc = FreeCAD.newDocument("MapSettings")
nom, meas = load_example(doc)
comp = make_map(doc, nom, meas)
vo = comp.ViewObject
scene = vo.Proxy.scene


def step(name, **values):
    before = len(report_view_text())
    for prop, value in values.items():
        setattr(vo, prop, value)
    Gui.updateGui()
    entry = legend_entries()[comp.Label]
    RESULTS[name] = {"texts": entry.texts(), "range": list(scene.range),
                     "tolerance": scene._style.tolerance, "warning": scene._style.warning,
                     "report": report_view_text()[before:]}
    return entry


step("auto")
step("range_inverted", AutoRange=False, RangeMin=0.03, RangeMax=-0.02)
entry = step("range_equal", RangeMin=0.02, RangeMax=0.02)
path = os.path.join(TMP, "legend_problem.png")
pix = entry.grab()
pix.save(path)
RESULTS["shot"] = [path, pix.width() / float(entry.width()),
                   [[t, r.x(), r.y(), r.width(), r.height()] for t, _f, r in entry.text_blocks()],
                   [entry.width(), entry.height()]]
step("range_right", RangeMin=-0.02, RangeMax=0.03)
step("band", AutoRange=True, TolBand=True, WarnBand=0.8)
step("warn_percent", WarnBand=80)
step("warn_right", WarnBand=0.8)
step("band_inverted", TolLow=0.02, TolHigh=0.01)
step("band_right", TolLow=-0.01)
RESULTS["errors_at_end"] = ERRORS[:]
