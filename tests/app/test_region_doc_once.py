# SPDX-License-Identifier: LGPL-2.1-or-later
"""The region document route computes the region once (issue 27: document recomputes do not
repeat work for the same inputs): the new measurement object, left touched, had the
document's recompute after the replace compute the region a second time."""

from surfcomp.app import region_doc
from tests.app import region_parts as rp


def test_the_region_is_computed_once_and_the_saved_document_is_up_to_date(tmp_path,
                                                                           monkeypatch):
    import FreeCAD

    path, csv, *_ = rp.g1_shop(tmp_path, 800, seed=3)
    calls = []
    compute = region_doc.compute

    def counted(obj, *args, **kwargs):
        calls.append(obj.Name)
        return compute(obj, *args, **kwargs)

    monkeypatch.setattr(region_doc, "compute", counted)
    out = str(tmp_path / "out.FCStd")
    r = rp.run(path, csv, "--object", "Block", "--faces", "auto", "--replace", "--save", out)
    assert r.returncode == 0, r.stderr
    assert calls == ["RegionCompensation"]
    assert "replaced the nominal in: Mirror.Source" in r.stdout
    doc = FreeCAD.openDocument(out)
    try:
        states = {o.Name: list(o.State) for o in doc.Objects}
        for name in ("RegionCompensation", "Measurement"):
            assert not {"Touched", "Invalid", "Error"} & set(states[name]), states
        region = doc.getObject("RegionCompensation")
        assert region.Shape.isValid() and len(region.Shape.Faces) == 7
        assert doc.getObject("Mirror").Source.Name == "RegionCompensation"
    finally:
        FreeCAD.closeDocument(doc.Name)
