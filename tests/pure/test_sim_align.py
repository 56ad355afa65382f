# SPDX-License-Identifier: LGPL-2.1-or-later
"""Alignment in the virtual machining loop (issue 28): what a best fit on the measured part
absorbs, and that a known transform round trip changes nothing."""

from numpy.testing import assert_allclose

from examples.make_example import example_surface
from surfcomp.core.measurement import align
from surfcomp.core.measurement.align_report import AlignOptions
from surfcomp.core.simulation import simulate as sm
from surfcomp.core.simulation.sim_align import SimAligner

#: a 25 um mean error (offset 20 um plus the default model's), no noise
MODEL = sm.MachiningModel(offset=0.02, sigma=0.0, probe_sigma=0.0)
LOOP = dict(grid=(11, 11), specs=sm.method_specs(("none", "offset")), replicas=1, between=1)


def _run(aligner=None):
    return sm.simulate(example_surface(), 1, MODEL, aligner=aligner, **LOOP)


def _mean(stats):
    return stats[0]["all"].mean


def test_known_transform_round_trip_changes_nothing():
    """Moved into a frame 12 deg and 54 mm away and back by --transform: the loop's results
    are those without alignment (1e-6 um), the record holds the transform."""
    T = align.work_offset([50.0, -20.0, 5.0], 12.0)
    plain = _run()
    aligner = SimAligner(example_surface(), 1, AlignOptions("none", transform=T))
    moved = _run(aligner)
    for label in ("none", "offset"):
        for key in ("mean", "std", "min", "max"):
            assert_allclose(getattr(moved.after[label][0]["all"], key),
                            getattr(plain.after[label][0]["all"], key), atol=1e-9)
    # one fit per compensating method and replica ('none' measures nothing it uses)
    assert [(lab, r) for lab, r, _a in aligner.records] == [("offset", 0)]
    d = aligner.as_dict()
    assert d["method"] == "none" and d["absorbed"] is None
    assert_allclose(d["matrix"], T, atol=1e-15)


def test_best_fit_on_the_face_absorbs_the_mean_error():
    """A z-only best fit on the compensated face takes the 25 um mean out of the measurement:
    the offset method then corrects nothing and the part keeps its mean error, while
    without the alignment it is corrected to 0; the reported absorbed offset is the mean
    the part keeps."""
    plain = _run()
    before = _mean(plain.before)
    assert 0.024 < before < 0.026
    assert abs(_mean(plain.after["offset"])) < 1e-6
    aligner = SimAligner(example_surface(), 1, AlignOptions("bestfit", dof="z"))
    fitted = _run(aligner)
    kept = _mean(fitted.after["offset"])
    assert abs(kept - before) < 0.5e-3                   # nearly all of the mean stays
    d = aligner.as_dict()
    assert d["converged"] and d["dof"] == ["z"]
    assert_allclose(d["absorbed"]["mean_offset_um"], -kept * 1e3, atol=0.05)
    assert d["simulated"]["fits"][0]["method"] == "offset"
    lines = aligner.summary()
    assert lines[0].startswith("Alignment:    bestfit") and "(replica 1, offset)" in lines[0]
    assert lines[-1].startswith("  offset: 1 fit(s), 1 converged; absorbed mean offset -24.7")
    # the part machined without compensation is the same either way
    assert_allclose(_mean(fitted.after["none"]), _mean(plain.after["none"]), atol=1e-12)


def test_without_points_between_nodes_the_between_figures_are_none():
    """between = 1 evaluates the nodes only: the report's 'between' figures were the
    nodes' own under the name of the points between them; they are None (null), and the
    'where' text says there are none."""
    res = _run()
    assert res.before[0]["between"] is None
    assert res.before[0]["grid"].count == 121 and res.before[0]["all"].count == 121
    d = res.as_dict()
    assert d["before"]["replicas"][0]["between"] is None
    assert d["before"]["spread"]["between"] is None
    assert d["before"]["spread"]["grid"] is not None
    assert d["where"].endswith("between = the points between nodes (none: between = 1)")
    two = sm.simulate(example_surface(), 1, MODEL, **dict(LOOP, between=2))
    assert two.before[0]["between"].count == 21 * 21 - 121
    assert "(none" not in two.as_dict()["where"]
