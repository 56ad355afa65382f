# SPDX-License-Identifier: LGPL-2.1-or-later
"""Make ``shop-0.20.FCStd`` (committed test data): a shop document saved by FreeCAD 0.20.

It holds every kind of surfcomp object a user's document can hold, as 0.20 saves them, so
that ``tests/app/test_old_documents.py`` can check on every FreeCAD of the version matrix
that such a document opens, restores and recomputes to the same result:

- ``Block``: a block whose top (``Face2``) is the example's free-form face;
- ``Meas1``, ``Meas2``: two measurement rounds (data inside the document, files deleted);
- ``Round1`` (solid output) and ``Round2`` (its iteration, ``Base = Round1``);
- a CAM Job on the block with a 3D Surface finishing operation (OpenCamLib) on ``Face2``,
  whose model now uses ``Round2`` (replace);
- ``DressupAxisErrors``: the axis-error dressup on that operation.

It is kept small (an 11 x 11 grid, coarse tool path) because it is committed.

Next to it, ``shop-0.20.json`` records what 0.20 computed (pole grid sizes, correction,
tool path, the dressup's result), to compare with after the reopen; the poles themselves are
in the document's saved shapes.

Run with FreeCAD 0.20 (Debian 12) only, from the repository root::

    /usr/bin/python3 tests/data/documents/make_shop_document.py
"""

import json
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, ROOT)

from surfcomp.app import fcenv  # noqa: E402

FreeCAD = fcenv.import_freecad()

import numpy as np  # noqa: E402

from surfcomp.app import cam, dressup_axis, features, cam_job, replace  # noqa: E402
from surfcomp.app.nominal import nominal_from_face  # noqa: E402
from surfcomp.core.axis.axis_errors import AxisErrorModel, SimulatedMachine  # noqa: E402
from tests.app.helpers import grid_on_face, write_cmm_csv  # noqa: E402
from tests.app.test_features import add_part, block_solid, error_model  # noqa: E402

DOCUMENT = os.path.join(HERE, "shop-0.20.FCStd")
EXPECTED = os.path.join(HERE, "shop-0.20.json")


def poles(shape, k):
    return [[list(p) for p in row] for row in shape.Faces[k].Surface.getPoles()]


def main():
    version = ".".join(FreeCAD.Version()[:2])
    if version != "0.20":
        sys.exit("run this with FreeCAD 0.20 (found %s): the file is 0.20's test data" % version)
    cam.setup_workbench()
    doc = FreeCAD.newDocument("shop020")
    solid = block_solid()
    block = add_part(doc, solid, "Block")
    nominal = nominal_from_face(solid.Faces[1], face_name="Face2")
    P, N, _, _ = grid_on_face(nominal, 11, 11, margin=0.0)
    rng = np.random.default_rng(20)
    with tempfile.TemporaryDirectory() as tmp:
        csv1, csv2 = os.path.join(tmp, "round1.csv"), os.path.join(tmp, "round2.csv")
        write_cmm_csv(csv1, P, N, error_model(P) + rng.normal(0, 5e-4, (11, 11)))
        write_cmm_csv(csv2, P, N, 0.2 * error_model(P) + rng.normal(0, 5e-4, (11, 11)))
        m1 = features.make_measurement(doc, csv1, name="Meas1")
        m2 = features.make_measurement(doc, csv2, name="Meas2")
    c1 = features.make_compensation(doc, block, "Face2", m1, output="solid", name="Round1")
    c2 = features.make_compensation(doc, block, "Face2", m2, base=c1, output="solid",
                                    name="Round2")
    c1.Refine = c2.Refine = 1
    job = cam_job.create_job(doc, [block])
    tc = cam_job.ball_end_tool_controller(job, 6.0)
    op = cam_job.surface_operation(job, block, ["Face2"], tc, step_over=100.0,
                                   sample_interval=3.0, linear_deflection=0.01)
    doc.recompute()
    replace.replace(doc, c2)
    model = AxisErrorModel.from_components(scale={"x": 1e-3}, positional={"z": (0.0, 2e-5)})
    data = SimulatedMachine(model).measure({"x": np.linspace(-10, 60, 8),
                                            "z": np.linspace(-10, 20, 7)})
    dressup = dressup_axis.Create(op, data)
    doc.recompute()
    bad = [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State]
    if bad:
        sys.exit("objects failed to recompute: %s" % bad)
    doc.saveAs(DOCUMENT)
    expected = {
        "freecad": ".".join(FreeCAD.Version()[:3]),
        "objects": sorted(o.Name for o in doc.Objects),
        "poles_shape": [np.shape(poles(c.Shape, 1)) for c in (c1, c2)],
        "correction2": list(c2.Correction),
        "cl": cam_job.cutter_locations(op).tolist(),
        "faces": len(c2.Shape.Faces), "volume2": c2.Shape.Volume,
        "dressup": {"base": dressup.Base.Name, "commands": len(dressup.Path.Commands),
                    "error_before": float(dressup.ErrorBefore), "error_after": float(dressup.ErrorAfter),
                    "max_correction": float(dressup.MaxCorrection)},
        "replaced_links": json.loads(c2.ReplacedLinks),
    }
    with open(EXPECTED, "w") as fh:
        json.dump(expected, fh, indent=1, sort_keys=True)
        fh.write("\n")
    print("wrote %s (%d bytes) and %s" % (DOCUMENT, os.path.getsize(DOCUMENT), EXPECTED))


if __name__ == "__main__":
    main()
