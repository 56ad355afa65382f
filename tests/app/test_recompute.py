# SPDX-License-Identifier: LGPL-2.1-or-later
"""The CAM operations recomputed in a child process (the GUI's Replace and Restore) end
exactly as a recompute in this process: same commands within 1e-9 mm, same other results,
each operation computed once, nothing left touched; a cancel stops the child and changes
nothing."""

import os
import shutil
import time

import numpy as np
import pytest

from surfcomp.app import cam, documents, progress, recompute, replace
from surfcomp.errors import ComputationError
from tests.conftest import ROOT

SHOP = os.path.join(ROOT, "tests", "data", "documents", "shop-0.20.FCStd")
#: finer than the committed document's operation (142 commands), a few seconds to compute
STEP_OVER = 40.0
#: finer still for the cancel (step over %, sample interval mm): the child must still be
#: computing the operation when the test cancels it, on a fast machine too (at 40 % and
#: 3 mm one finished within a second; at 2 % and 0.2 mm it takes many); it is killed then,
#: so the finer operation costs the test nothing
CANCEL_FINE = (2.0, 0.2)


def restored_shop(folder, name, step_over=STEP_OVER, sample=None):
    """A copy of the shop document with a finer Surface operation, after Restore (the model
    clone uses the block again): the operation and its dressup need a recompute."""
    cam.setup_workbench()
    path = os.path.join(str(folder), name + ".FCStd")
    shutil.copyfile(SHOP, path)
    doc, _refused, _info = documents.open_document(path)
    # FreeCAD 1.x opens the 0.20 document with its objects touched (their properties were
    # brought up to date): recompute them first, with the committed coarse operation
    progress.recompute_with_progress(doc, "open")
    doc.getObject("Surface").StepOver = step_over
    if sample is not None:
        doc.getObject("Surface").SampleInterval = sample
    replace.restore(doc, doc.getObject("Round2"))
    return doc


def count_executions(op):
    calls = [0]
    real = op.Proxy.opExecute

    def counted(*args, **kwargs):
        calls[0] += 1
        return real(*args, **kwargs)

    op.Proxy.opExecute = counted
    return calls


def commands(obj):
    return [(c.Name, dict(c.Parameters)) for c in obj.Path.Commands]


def assert_same_path(a, b, atol):
    assert [n for n, _p in a] == [n for n, _p in b]
    assert [sorted(p) for _n, p in a] == [sorted(p) for _n, p in b]
    x = np.array([p[k] for _n, p in a for k in sorted(p)])
    y = np.array([p[k] for _n, p in b for k in sorted(p)])
    np.testing.assert_allclose(x, y, rtol=0, atol=atol)


def same_shape(a, b, atol=1e-9):
    """The same topology counts, vertices within ``atol`` mm, volume and area within 1e-9."""
    if a.isNull() or b.isNull():
        return a.isNull() and b.isNull()
    counts = [(len(s.Solids), len(s.Faces), len(s.Edges), len(s.Vertexes)) for s in (a, b)]
    if counts[0] != counts[1]:
        return False
    va = np.array([v.Point for v in a.Vertexes]).reshape(-1, 3)
    vb = np.array([v.Point for v in b.Vertexes]).reshape(-1, 3)
    return bool(np.all(np.abs(va - vb) <= atol)) and \
        abs(a.Volume - b.Volume) <= 1e-9 * max(1.0, abs(a.Volume)) and \
        abs(a.Area - b.Area) <= 1e-9 * max(1.0, a.Area)


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    """The same recompute in this process and through the child."""
    import FreeCAD

    folder = tmp_path_factory.mktemp("recompute")
    here = restored_shop(folder, "here")
    there = restored_shop(folder, "there")
    calls_here = count_executions(here.getObject("Surface"))
    calls_there = count_executions(there.getObject("Surface"))
    todo_here = [o.Name for o in progress.pending(here)]
    progress.recompute_with_progress(here, "in process")
    job = recompute.ChildRecompute(there)
    todo_there = [o.Name for o in job.todo]
    job.start()
    while job.poll():
        time.sleep(0.05)
    done = job.finish()
    yield {"here": here, "there": there, "calls_here": calls_here[0],
           "calls_there": calls_there[0], "child": job.executions, "heavy": job.heavy,
           "todo": (todo_here, todo_there), "done": done}
    for d in (here, there):
        FreeCAD.closeDocument(d.Name)


def test_pending_objects_in_dependency_order(both):
    todo_here, todo_there = both["todo"]
    assert todo_here == todo_there == both["done"]
    # each after what it links: the operation after the model clone, the dressup after the
    # operation, the Job after its operations
    for name in ("Clone", "Surface", "DressupAxisErrors", "Job"):
        assert name in todo_here
    assert "Round2" not in todo_here        # its replace record is no input of its own
    for before, after in (("Clone", "Surface"), ("Surface", "DressupAxisErrors"),
                          ("DressupAxisErrors", "Job")):
        assert todo_here.index(before) < todo_here.index(after)
    assert both["heavy"] == {"Surface", "DressupAxisErrors"}


def test_each_operation_is_computed_once(both):
    assert both["calls_here"] == 1              # in process: once, not once more at the end
    assert both["calls_there"] == 0             # through the child: not at all here ...
    assert both["child"] == {"Surface": 1}      # ... and once in the child
    for doc in (both["here"], both["there"]):
        assert [o.Name for o in doc.Objects if o.State != ["Up-to-date"]] == []


def test_child_gives_the_in_process_result(both):
    here, there = both["here"], both["there"]
    for name in ("Surface", "DressupAxisErrors"):
        a, b = commands(here.getObject(name)), commands(there.getObject(name))
        assert len(a) > 300
        assert_same_path(a, b, atol=1e-9)
    assert_same_path(commands(here.getObject("Job")), commands(there.getObject("Job")), 1e-9)
    # every other result too (cycle times, the dressup's figures, the Stock's box); shapes by
    # their geometry: FreeCAD 1.x saves a shape with the tessellation an operation left on it
    differ = []
    for o in here.Objects:
        other = there.getObject(o.Name)
        for prop in o.PropertiesList:
            if prop in ("Proxy", "ExpressionEngine", "Path"):
                continue
            if o.getTypeIdOfProperty(prop) == "Part::PropertyPartShape":
                same = same_shape(getattr(o, prop), getattr(other, prop))
            else:
                same = recompute._content(o, prop) == recompute._content(other, prop)
            if not same:
                differ.append("%s.%s" % (o.Name, prop))
    assert differ == []


def test_cancel_stops_the_child_and_changes_nothing(tmp_path):
    import FreeCAD

    doc = restored_shop(tmp_path, "cancel", *CANCEL_FINE)
    op = doc.getObject("Surface")
    calls = count_executions(op)
    before = commands(op)
    job = recompute.ChildRecompute(doc).start()
    tmp = job.tmp
    # cancelled while the child computes the operation (its status names it)
    deadline = time.monotonic() + 60
    while job.poll() and job.status()[2] != op.Label and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.2)
    assert job.poll() and job.status()[2] == op.Label
    t0 = time.perf_counter()
    job.cancel()
    assert time.perf_counter() - t0 < 1.0
    assert job.proc.returncode is not None and not job.poll()
    assert not os.path.exists(tmp)
    assert commands(op) == before and calls[0] == 0
    FreeCAD.closeDocument(doc.Name)


def test_a_failing_child_is_reported_and_changes_nothing(tmp_path):
    import FreeCAD

    doc = restored_shop(tmp_path, "crash")
    op = doc.getObject("Surface")
    before = commands(op)
    job = recompute.ChildRecompute(doc).start()
    job.proc.kill()         # as a crash of the child would end it
    job.proc.wait()
    with pytest.raises(ComputationError, match="recompute process failed"):
        job.finish()
    assert commands(op) == before and "Touched" in op.State
    FreeCAD.closeDocument(doc.Name)


