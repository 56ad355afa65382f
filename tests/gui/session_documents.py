# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_documents.py: a document saved with a map opens unmodified (issue 24),
# and the Preferences dialog shows the SurfComp page with its icon.
import shutil  # noqa: E402

from surfcomp.app import features  # noqa: E402


def settle_open(path):
    """Open ``path`` as File > Open does and let the deferred drawing run."""
    d = FreeCAD.openDocument(path)
    for _ in range(40):
        Gui.updateGui()
        time.sleep(0.02)
    return d


doc = FreeCAD.newDocument("Saved")
comp = make_map(doc, *load_example(doc))
name = comp.Name
saved = os.path.join(TMP, "saved.FCStd")
doc.saveAs(saved)
FreeCAD.closeDocument(doc.Name)
Gui.updateGui()
again = settle_open(saved)
vobj = again.getObject(name).ViewObject
RESULTS["reopened"] = {"modified": bool(Gui.getDocument(again.Name).Modified),
                       "proxy": type(vobj.Proxy).__name__, "mode": vobj.DisplayMode,
                       "drawn": vobj.Proxy.scene.surface_colors.rgb.getNum()}
# a change after opening still marks it modified
vobj.RangeMin = -0.1
RESULTS["modified_after_change"] = bool(Gui.getDocument(again.Name).Modified)
FreeCAD.closeDocument(again.Name)

# an old document made headless (FreeCAD 0.20's freecadcmd): its surfcomp objects are
# migrated and get their view providers and maps while it opens, and it opens unmodified
old = os.path.join(TMP, "shop-0.20.FCStd")
shutil.copyfile(os.path.join(ROOT, "tests", "data", "documents", "shop-0.20.FCStd"), old)
shop = settle_open(old)
RESULTS["old_document"] = {
    "modified": bool(Gui.getDocument(shop.Name).Modified),
    "views": {o.Name: [type(o.ViewObject.Proxy).__name__, o.ViewObject.DisplayMode,
                       o.ViewObject.Proxy.scene.surface_colors.rgb.getNum()]
              for o in shop.Objects if o.Name in ("Round1", "Round2")},
    "versions": [shop.getObject(n).Version for n in ("Meas1", "Round1", "Round2")],
    "version": features.VERSION,
    "renamed": ["EdgeTol" in shop.getObject("Round2").PropertiesList,
                "EdgeTolerance" in shop.getObject("Round2").PropertiesList]}
FreeCAD.closeDocument(shop.Name)

# -- the Preferences dialog: the SurfComp group and its icon --------------------------------
PREFS = {}


def inspect_preferences():
    dlg = QtGui.QApplication.activeModalWidget()
    try:
        found = []
        for lst in dlg.findChildren(QtGui.QListWidget):
            for i in range(lst.count()):
                item = lst.item(i)
                found.append([item.text(), item.icon().isNull()])
        for tree in dlg.findChildren(QtGui.QTreeView):
            model = tree.model()
            for r in range(model.rowCount() if model is not None else 0):
                idx = model.index(r, 0)
                icon = model.data(idx, QtCore.Qt.DecorationRole)
                null = icon is None or (hasattr(icon, "isNull") and icon.isNull())
                found.append([model.data(idx, QtCore.Qt.DisplayRole), null])
        PREFS["groups"] = found
        path = os.path.join(TMP, "preferences.png")
        dlg.grab().save(path)
        PREFS["png"] = path
    finally:
        dlg.reject()


QtCore.QTimer.singleShot(1500, inspect_preferences)
Gui.runCommand("Std_DlgPreferences")
RESULTS["preferences"] = PREFS
shutil.copy(os.path.join(ROOT, "resources", "icons", "preferences-surfcomp.svg"), TMP)
RESULTS["errors_at_end"] = ERRORS[:]
