# SPDX-License-Identifier: LGPL-2.1-or-later
"""Replace in document and Restore nominal with a region object, in the real FreeCAD GUI
(under Xvfb), on a document opened from disk (issue 30): the block's two G1 top faces
compensated together by ``compensate DOC --faces Face1,Face2 --save``, a mirror of the
block as the nominal's user. Clicks on the tree and the toolbar: with the nominal selected
the commands say what to select and change nothing; with the region object, Replace moves
the mirror to the corrected block and Restore moves it back, each one undo step."""

import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT
from tests.gui.harness import build_document, read_image, run_session

MAKE = r'''
import os, sys
sys.path.insert(0, os.environ["SURFCOMP_ROOT"])
import FreeCAD
from tests.app import region_parts as rp
solid, tops = rp.g1_top_solid()
doc = FreeCAD.newDocument("regionreplace")
block = doc.addObject("Part::Feature", "Block")
block.Shape = solid
mirror = doc.addObject("Part::Mirroring", "Mirror")
mirror.Source = block
mirror.Normal = FreeCAD.Vector(1, 0, 0)
mirror.Base = FreeCAD.Vector(25, 0, 0)
doc.recompute()
doc.saveAs(os.environ["SURFCOMP_DOC"])
pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 3000, rp.ridge_field, seed=1)
rp.write_csv(os.environ["SURFCOMP_CSV"], pts, nrm, dev)
with open(os.environ["SURFCOMP_CSV"] + ".volume", "w") as fh:
    fh.write(repr(solid.Volume))
'''


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gui_region_replace")
    shop, csv = str(tmp / "shop.FCStd"), str(tmp / "g1.csv")
    p = build_document(tmp, MAKE, shop, csv)
    assert os.path.isfile(shop) and os.path.isfile(csv + ".volume"), p.stdout + p.stderr
    with open(csv + ".volume") as fh:
        volume = float(fh.read())
    out = str(tmp / "region.FCStd")
    r = subprocess.run([sys.executable, "-m", "surfcomp", "compensate", shop, csv, "--object",
                        "Block", "--faces", "Face1,Face2", "--save", out], cwd=ROOT,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    res = run_session("region_replace", tmp, env={"SURFCOMP_REGION_DOC": out})
    res["nominal_volume"] = volume
    return res


def test_session_ran_without_exceptions(session):
    assert session["errors"] == [], session["errors"]
    assert session["errors_at_end"] == []


def test_document_opened_from_disk(session):
    module, source, _block_visible, _region_visible, volume, nominal, mirror = \
        session["opened"]
    assert module == "surfcomp.app.region_doc" and source == "Block"
    assert nominal == pytest.approx(session["nominal_volume"], abs=1e-9)
    assert mirror == pytest.approx(nominal, abs=1e-6)
    assert volume - nominal == pytest.approx(-0.64, abs=0.02)


def test_wrong_selection_is_told_what_to_select(session):
    assert session["pick_block"] == ["Block"]
    enabled, errors, infos, before, after = session["wrong_replace"]
    assert enabled and infos == []
    (title, message), = errors
    assert title.endswith("Replace in document")
    assert message == ("Select one compensation or region compensation (in the tree or the "
                       "3D view): its result takes the nominal's place, then run Replace in "
                       "document; the selection holds Block")
    assert after == before and after["source"] == "Block" and not after["record"]
    enabled, errors, after = session["wrong_restore"]
    assert enabled and len(errors) == 1
    assert errors[0][1].startswith("Select the one compensation or region compensation that "
                                   "replaces its nominal")
    assert after == before


def test_replace_moves_the_user_to_the_region_in_one_undo_step(session):
    assert session["pick_region"] == ["RegionCompensation"]
    assert session["enabled_before"] == [True, False]
    enabled, errors, infos, before, after = session["replace"]
    assert enabled and errors == []
    (title, text), = infos
    assert title == "Replace in document"
    assert text.startswith("Rebound 1 link(s) of 1 object(s): Mirror")
    assert "Path jobs: none" in text
    assert after["source"] == "RegionCompensation" and after["record"]
    assert not after["block_visible"] and after["region_visible"]
    assert after["undo"] == before["undo"] + 1
    # the mirror now mirrors the corrected block: 0.64 mm^3 of the ridge gone
    assert after["mirror_volume"] - before["mirror_volume"] == pytest.approx(-0.64, abs=0.02)
    assert session["enabled_after"] == [False, True]


def test_undo_puts_the_nominal_back(session):
    assert session["undo_enabled"]
    after = session["after_undo"]
    assert after["source"] == "Block" and not after["record"] and after["block_visible"]
    assert not after["region_visible"]
    again = session["after_undo_recompute"]
    assert again["mirror_volume"] == pytest.approx(session["nominal_volume"], abs=1e-6)


def test_restore_puts_the_user_back_and_undo_replaces_again(session):
    replaced, errors = session["replaced_again"]
    assert errors == [] and replaced["source"] == "RegionCompensation"
    enabled, errors, infos, before, after = session["restore"]
    assert enabled and errors == []
    (title, text), = infos
    assert title == "Restore nominal" and text.startswith("Restored 1 link(s) of 1 object(s)")
    assert after["source"] == "Block" and not after["record"] and after["block_visible"]
    assert after["undo"] == before["undo"] + 1
    assert after["mirror_volume"] == pytest.approx(session["nominal_volume"], abs=1e-6)
    undone = session["after_undo_restore"]
    assert undone["source"] == "RegionCompensation" and undone["record"]
    assert undone["mirror_volume"] - session["nominal_volume"] == pytest.approx(-0.64,
                                                                               abs=0.02)


def test_screenshots_show_the_solids(session):
    for name in ("shot_replaced", "shot_restored"):
        img = read_image(session[name])
        assert (img.sum(axis=2) < 2.7).mean() > 0.05
