# SPDX-License-Identifier: LGPL-2.1-or-later
"""Replace the nominal by the compensation and restore it: links, visibility, failure safety."""

import json

import FreeCAD
import numpy as np
import pytest

from surfcomp.app import cam, features, replace
from surfcomp.app.nominal import nominal_from_face
from surfcomp.errors import GeometryError, InputError
from tests.app.helpers import grid_on_face, write_cmm_csv
from tests.app.test_features import add_part, block_solid, error_model


class _User:
    """A plain user of the nominal: links of every kind Path and other features use."""

    def __init__(self, obj):
        obj.addProperty("App::PropertyLink", "Source", "Test", "")
        obj.addProperty("App::PropertyLinkList", "Sources", "Test", "")
        obj.addProperty("App::PropertyLinkSub", "Edge", "Test", "")
        obj.addProperty("App::PropertyLinkSubListGlobal", "Faces", "Test", "")
        obj.Proxy = self

    def execute(self, obj):
        pass


def make_user(doc, name="User"):
    obj = doc.addObject("App::FeaturePython", name)
    _User(obj)
    return obj


def snapshot(doc):
    """Every link property, visibility, record and touched state of the document."""
    out = {}
    for o in doc.Objects:
        for prop in o.PropertiesList:
            kind = replace._kind(o.getTypeIdOfProperty(prop))
            if kind:
                out[(o.Name, prop)] = replace._encode(kind, getattr(o, prop))
        out[(o.Name, "Visibility")] = o.Visibility
        out[(o.Name, "touched")] = "Touched" in o.State
        if features.is_compensation(o):
            out[(o.Name, "ReplacedLinks")] = o.ReplacedLinks
    out["objects"] = [o.Name for o in doc.Objects]
    return out


@pytest.fixture
def setup():
    """A block (Face2 free-form), a compensation with solid output, a Draft clone of the
    block and a user with links of every kind; all computed."""
    cam.setup_workbench(require_ocl=False)
    import Draft

    doc = FreeCAD.newDocument("replace")
    solid = block_solid()
    nom = add_part(doc, solid, "Block")
    nominal = nominal_from_face(solid.Faces[1], face_name="Face2")
    P, N, _, _ = grid_on_face(nominal, 11, 11, margin=0.0)
    write_cmm_csv(doc.TransientDir + "/m.csv", P, N, error_model(P))
    m = features.make_measurement(doc, doc.TransientDir + "/m.csv")
    comp = features.make_compensation(doc, nom, "Face2", m, output="solid")
    clone = Draft.clone(nom)
    other = add_part(doc, solid.copy(), "Other")
    user = make_user(doc)
    user.Source = nom
    user.Sources = [other, nom]
    user.Edge = (nom, ["Edge3"])
    user.Faces = [(nom, ("Face2", "Face6")), (other, ("Face1",))]
    doc.recompute()
    for o in doc.Objects:
        assert "Invalid" not in o.State, o.Name
    yield doc, nom, comp, clone, other, user
    FreeCAD.closeDocument(doc.Name)


def test_replace_rebinds_every_user_and_restore_undoes_it(setup):
    doc, nom, comp, clone, other, user = setup
    nominal_shape = nom.Shape.copy()
    before = snapshot(doc)
    changed = replace.replace(doc, comp)
    assert sorted(changed) == sorted([(clone.Name, "Objects"), (user.Name, "Source"),
                                      (user.Name, "Sources"), (user.Name, "Edge"),
                                      (user.Name, "Faces")])
    assert clone.Objects == [comp]
    assert user.Source == comp and user.Sources == [other, comp]
    assert user.Edge == (comp, ["Edge3"])
    assert user.Faces == [(comp, ("Face2", "Face6")), (other, ("Face1",))]
    # the compensation keeps its own links; the nominal is hidden, not modified
    assert comp.Nominal == nom and nom.Visibility is False and comp.Visibility is True
    np.testing.assert_array_equal(nom.Shape.Faces[1].Surface.getPoles(),
                                  nominal_shape.Faces[1].Surface.getPoles())
    assert "Touched" not in nom.State
    assert replace.is_replacing(comp)
    record = json.loads(comp.ReplacedLinks)
    assert {(r["object"], r["property"]) for r in record["links"]} == set(changed)
    doc.recompute()
    # the clone now carries the corrected solid; Face2 is the corrected surface
    assert len(clone.Shape.Faces) == 6 and clone.Shape.isValid()
    np.testing.assert_allclose(clone.Shape.Faces[1].Surface.getPoles(),
                               comp.Shape.Faces[1].Surface.getPoles(), atol=1e-12)
    with pytest.raises(InputError, match="already replaces its nominal"):
        replace.replace(doc, comp)
    put_back = replace.restore(doc, comp)
    assert sorted(put_back) == sorted(changed)
    doc.recompute()
    after = snapshot(doc)
    for key in before:
        if key[1] != "touched":
            assert after[key] == before[key], key
    with pytest.raises(InputError, match="does not replace its nominal"):
        replace.restore(doc, comp)


def test_the_summary_counts_only_links_restore_can_put_back(setup):
    """A rebound user deleted after the replace: Restore skips it, and the summary the GUI
    shows (taken before the restore) neither counts its links nor hides it."""
    doc, nom, comp, clone, other, user = setup
    replace.replace(doc, comp)
    doc.recompute()
    assert replace.summary(doc, comp)["links"] == 5
    doc.removeObject(user.Name)
    s = replace.summary(doc, comp)
    put_back = replace.restore(doc, comp)
    assert put_back == [(clone.Name, "Objects")]
    assert s["links"] == len(put_back) == 1 and s["deleted"] == ["User"]


@pytest.mark.parametrize("step", [1, 3, 6])
def test_a_failure_leaves_the_document_exactly_as_before(setup, monkeypatch, step):
    doc, nom, comp, clone, other, user = setup
    before = snapshot(doc)
    calls = []
    real_set = replace._Undo.set

    def failing_set(self, o, prop, value):
        calls.append(prop)
        if len(calls) == step:
            raise RuntimeError("injected failure at change %d" % step)
        return real_set(self, o, prop, value)

    monkeypatch.setattr(replace._Undo, "set", failing_set)
    with pytest.raises(RuntimeError, match="injected failure"):
        replace.replace(doc, comp)
    assert len(calls) == step
    assert snapshot(doc) == before                   # links, visibility, record, touched


def test_a_failed_restore_keeps_the_replaced_state(setup, monkeypatch):
    doc, nom, comp, clone, other, user = setup
    replace.replace(doc, comp)
    doc.recompute()
    replaced = snapshot(doc)
    real_set = replace._Undo.set
    calls = []

    def failing_set(self, o, prop, value):
        calls.append(prop)
        if len(calls) == 4:
            raise RuntimeError("injected")
        return real_set(self, o, prop, value)

    monkeypatch.setattr(replace._Undo, "set", failing_set)
    with pytest.raises(RuntimeError):
        replace.restore(doc, comp)
    assert snapshot(doc) == replaced


def test_face_output_cannot_replace_a_face_of_a_cloned_solid(setup):
    doc, nom, comp, clone, other, user = setup
    comp.Output = "face"
    doc.recompute()
    before = snapshot(doc)
    with pytest.raises(GeometryError, match=r"^User.Edge links Edge3 of the nominal, which the "
                                            r"face output of Compensation does not have: set "
                                            r"Compensation's Output to solid"):
        replace.replace(doc, comp)
    assert snapshot(doc) == before
    user.Edge = None
    user.Faces = []
    doc.recompute()
    before = snapshot(doc)
    with pytest.raises(GeometryError, match=r"Block is cloned by Clone: with the face output a "
                                            r"clone would keep only the compensated face of the "
                                            r"6 faces"):
        replace.replace(doc, comp)
    assert snapshot(doc) == before


def test_an_invalid_compensation_is_not_put_in(setup):
    doc, nom, comp, clone, other, user = setup
    comp.MaskSize = 4
    doc.recompute()
    assert "Invalid" in comp.State
    before = snapshot(doc)
    with pytest.raises(InputError, match="is not computed"):
        replace.replace(doc, comp)
    assert snapshot(doc) == before


def test_iteration_moves_users_from_the_previous_round(setup):
    doc, nom, comp, clone, other, user = setup
    replace.replace(doc, comp)
    second = features.make_compensation(doc, nom, "Face2", comp.Measurement, base=comp,
                                        output="solid", name="Round2")
    doc.recompute()
    changed = replace.replace(doc, second)
    assert clone.Objects == [second] and user.Source == second
    assert user.Faces == [(second, ("Face2", "Face6")), (other, ("Face1",))]
    assert comp.Visibility is False and second.Visibility is True
    # links to the nominal and the first round do not go into a cycle
    assert second.Base == comp and comp.Nominal == nom and second.Nominal == nom
    assert (clone.Name, "Objects") in changed
    # the first round cannot be restored while the second replaces it (its users would go
    # from the second round to the nominal, and the second round's record would point at
    # links that no longer use it)
    before = snapshot(doc)
    with pytest.raises(InputError, match="Round2, a later round of its iteration, replaces "
                                         "it now; restore Round2 first"):
        replace.restore(doc, comp)
    assert snapshot(doc) == before
    replace.restore(doc, second)
    assert clone.Objects == [comp] and user.Source == comp and comp.Visibility is True
    replace.restore(doc, comp)
    assert clone.Objects == [nom] and user.Source == nom and nom.Visibility is True


def test_undo_in_the_document(setup):
    """With undo on (as in the GUI), one replace is one undo step."""
    doc, nom, comp, clone, other, user = setup
    doc.UndoMode = 1
    before = snapshot(doc)
    count = doc.UndoCount
    replace.replace(doc, comp)
    assert doc.UndoCount == count + 1
    assert doc.UndoNames[0].startswith("Replace Block by Compensation")
    doc.undo()
    after = snapshot(doc)
    for key in before:
        if key[1] != "touched":
            assert after[key] == before[key], key


def test_nothing_to_replace_is_refused_and_the_document_unchanged(setup):
    doc, nom, comp, clone, other, user = setup
    for o in (clone, user):
        doc.removeObject(o.Name)
    doc.recompute()
    before = snapshot(doc)
    with pytest.raises(InputError, match="nothing in the document uses Block"):
        replace.replace(doc, comp)
    assert snapshot(doc) == before


def test_clones_named_after_the_nominal_are_renamed_and_named_back(setup):
    """Path's model clone keeps the label "Model-<nominal>" (issue 13): Replace names it
    after the compensation, Restore gives the old label back; summary() tells both."""
    doc, nom, comp, clone, other, user = setup
    clone.Label = "Model-Block"
    replace.replace(doc, comp)
    assert clone.Label == "Model-Compensation"
    s = replace.summary(doc, comp)
    assert s["links"] == 5 and sorted(s["objects"]) == sorted([clone.Label, user.Label])
    assert s["renamed"] == [("Model-Block", "Model-Compensation")] and s["jobs"] == []
    replace.restore(doc, comp)
    assert clone.Label == "Model-Block"


def test_set_label_gives_a_free_label_exactly_and_leaves_the_preference(fresh_doc):
    """cam.set_label: a label no other object carries is set as given (FreeCAD 1.1 in the
    GUI added "001" to a label its count still held, tests/gui/test_region_replace_job_gui.py);
    a label another object carries still gets FreeCAD's suffix; the DuplicateLabels
    preference is as before, absent or set."""
    prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Document")
    had = "DuplicateLabels" in prefs.GetBools()
    kept = prefs.GetBool("DuplicateLabels", False)
    a = fresh_doc.addObject("Part::Feature", "A")
    b = fresh_doc.addObject("Part::Feature", "B")
    try:
        prefs.RemBool("DuplicateLabels")
        cam.set_label(a, "Model-Block")
        assert a.Label == "Model-Block" and "DuplicateLabels" not in prefs.GetBools()
        cam.set_label(b, "Model-Block")
        assert b.Label == "Model-Block001"
        prefs.SetBool("DuplicateLabels", False)
        cam.set_label(a, "Model-Other")
        assert a.Label == "Model-Other"
        assert prefs.GetBool("DuplicateLabels", True) is False
    finally:
        if had:
            prefs.SetBool("DuplicateLabels", kept)
        else:
            prefs.RemBool("DuplicateLabels")
