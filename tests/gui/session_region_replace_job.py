# SPDX-License-Identifier: LGPL-2.1-or-later
# GUI session of test_region_replace_job_gui.py: a shop document with a CAM Job (a 3D Surface
# operation over the block's two top faces) and a region object of those faces, opened from
# disk and the region object touched (to be recomputed); the region object picked in the
# tree, Replace in document, Undo, Replace, Restore nominal, Replace once more (the region
# object touched again), each with real clicks on the tree and the toolbar; after each the
# operation's cutter locations and the objects FreeCAD marks invalid.
import os

from surfcomp.app import cam_job

doc = FreeCAD.openDocument(os.environ["SURFCOMP_REGION_DOC"])
Gui.updateGui()
region, block, clone, op = (doc.getObject(n) for n in ("RegionCompensation", "Block", "Clone",
                                                       "Surface"))


def state():
    return {"source": [o.Name for o in clone.Objects], "record": bool(region.ReplacedLinks),
            "undo": doc.UndoCount, "base": [[o.Name, list(subs)] for o, subs in op.Base],
            "invalid": ["%s: %s" % (o.Name, o.getStatusString()) for o in doc.Objects
                        if "Invalid" in o.State or "Error" in o.State],
            "touched": [o.Name for o in doc.Objects if "Touched" in o.State],
            "labels": {o.Name: o.Label for o in doc.Objects},
            "tips": cam_job.cutter_locations(op).tolist()}


def step(command):
    """Pick the region object in the tree and click ``command``'s button: whether it was
    enabled, the errors and messages it showed, and the document's state after it."""
    click_tree(region.Label)
    del ERRORS[:], INFOS[:]
    enabled = press(command)
    return [enabled, ERRORS[:], INFOS[:], state()]


RESULTS["opened"] = [FreeCAD.Version()[0], type(region.Proxy).__module__, state()]
# the region object to be recomputed (as after a change of one of its options): Replace
# recomputes it with its users, so its shape is the one built now, not the one read from
# the file
region.touch()
RESULTS["touched"] = state()["touched"]
RESULTS["replace"] = step("SurfComp_ReplaceInDocument")
del INFOS[:]
RESULTS["undo_enabled"] = press("Std_Undo")
doc.recompute()
RESULTS["after_undo"] = state()
RESULTS["replace_again"] = step("SurfComp_ReplaceInDocument")
RESULTS["restore"] = step("SurfComp_RestoreNominal")
region.touch()
RESULTS["replace_third"] = step("SurfComp_ReplaceInDocument")
RESULTS["errors_at_end"] = ERRORS[:]
RESULTS["report_view_end"] = report_view_text()
