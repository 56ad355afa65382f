# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_region_replace_gui.py: a document with a region object opened from
# disk; the nominal picked in the tree and Replace in document clicked on the toolbar (told
# what to select); the region object picked, Replace, Undo, Replace, Restore nominal, Undo,
# each with real clicks on the tree and the toolbar; screenshots.
import os

doc = FreeCAD.openDocument(os.environ["SURFCOMP_REGION_DOC"])
Gui.updateGui()
region, block, mirror = (doc.getObject(n) for n in ("RegionCompensation", "Block", "Mirror"))
RESULTS["opened"] = [type(region.Proxy).__module__, mirror.Source.Name,
                     block.ViewObject.Visibility, region.ViewObject.Visibility,
                     region.Shape.Volume, block.Shape.Volume, mirror.Shape.Volume]
# the block drawn, the region object hidden: the state Replace records and Restore brings back
block.ViewObject.Visibility = True
region.ViewObject.Visibility = False
mirror.ViewObject.Visibility = True
Gui.updateGui()


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


def state():
    return {"source": mirror.Source.Name, "block_visible": block.ViewObject.Visibility,
            "region_visible": region.ViewObject.Visibility, "record": bool(region.ReplacedLinks),
            "undo": doc.UndoCount, "mirror_volume": mirror.Shape.Volume,
            "touched": [o.Name for o in doc.Objects if "Touched" in o.State]}


view = Gui.ActiveDocument.ActiveView
view.viewIsometric()
view.fitAll()
settle(view)
RESULTS["undo_mode"] = doc.UndoMode


# -- the nominal selected: Replace clicked, told what to select, nothing changes ----------
RESULTS["pick_block"] = click_tree(block.Label)
before = state()
del ERRORS[:], INFOS[:]
RESULTS["wrong_replace"] = [press("SurfComp_ReplaceInDocument"), ERRORS[:], INFOS[:],
                            before, state()]
del ERRORS[:]
RESULTS["wrong_restore"] = [press("SurfComp_RestoreNominal"), ERRORS[:], state()]
del ERRORS[:]

# -- the region object selected: Replace ----------------------------------------------------
RESULTS["pick_region"] = click_tree(region.Label)
RESULTS["enabled_before"] = [button("SurfComp_ReplaceInDocument")[0].isEnabled(),
                             button("SurfComp_RestoreNominal")[0].isEnabled()]
before = state()
RESULTS["replace"] = [press("SurfComp_ReplaceInDocument"), ERRORS[:], INFOS[:], before,
                      state()]
RESULTS["enabled_after"] = [button("SurfComp_ReplaceInDocument")[0].isEnabled(),
                            button("SurfComp_RestoreNominal")[0].isEnabled()]
Gui.Selection.clearSelection()
settle(view)
RESULTS["shot_replaced"] = shot(view, "region_replaced")

# -- one undo step puts everything back ------------------------------------------------------
del INFOS[:]
RESULTS["undo_enabled"] = press("Std_Undo")
RESULTS["after_undo"] = state()
doc.recompute()
RESULTS["after_undo_recompute"] = state()

# -- Replace again, then Restore nominal, then undo the Restore ------------------------------
click_tree(region.Label)
del INFOS[:], ERRORS[:]
press("SurfComp_ReplaceInDocument")
RESULTS["replaced_again"] = [state(), ERRORS[:]]
click_tree(region.Label)
before = state()
del INFOS[:], ERRORS[:]
RESULTS["restore"] = [press("SurfComp_RestoreNominal"), ERRORS[:], INFOS[:], before, state()]
Gui.Selection.clearSelection()
settle(view)
RESULTS["shot_restored"] = shot(view, "region_restored")
press("Std_Undo")
doc.recompute()
RESULTS["after_undo_restore"] = state()
RESULTS["errors_at_end"] = ERRORS[:]
RESULTS["report_view_end"] = report_view_text()
