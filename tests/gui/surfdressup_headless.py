# SPDX-License-Identifier: LGPL-2.1-or-later
"""Made headless for session_surfdressup.py (argv: repository root, output document): the
example nominal face, its measurements and a filtered compensation, a CAM Job on the
nominal with a 6 mm ball end tool controller, and a finishing operation "Finish" whose
path rides the nominal face: zigzag rows of a 3 mm ball's tool tip (its centre 3 mm along
the outward normal, the tip 3 mm below the centre). No 3D Surface operation, so OpenCamLib
need not be installed."""
import os
import sys

sys.path.insert(0, sys.argv[1])
from surfcomp.app import cam, fcenv  # noqa: E402

FreeCAD = fcenv.import_freecad()
import Part  # noqa: E402
import Path  # noqa: E402

from surfcomp.app import cam_job, features  # noqa: E402

R = 3.0
cam.setup_workbench()
root = sys.argv[1]
doc = FreeCAD.newDocument("surfdressup")
nominal = doc.addObject("Part::Feature", "Nominal")
nominal.Shape = Part.read(os.path.join(root, "examples", "nominal.step"))
meas = features.make_measurement(doc, os.path.join(root, "examples", "measurements.csv"))
comp = features.make_compensation(doc, nominal, "Face1", meas)
doc.recompute()
job = cam_job.create_job(doc, [nominal])
tc = cam_job.ball_end_tool_controller(job, 2 * R)
op = cam.module("Custom").Create("Finish")      # a CAM Custom operation: G-code lines
op.ToolController = tc
face = nominal.Shape.Faces[0]
u0, u1, v0, v1 = face.ParameterRange
rows, cols = 12, 40
cmds = []
for j in range(rows):
    v = v0 + (v1 - v0) * (0.05 + 0.9 * j / (rows - 1))
    us = [u0 + (u1 - u0) * (0.05 + 0.9 * i / (cols - 1)) for i in range(cols)]
    for k, u in enumerate(us if j % 2 == 0 else us[::-1]):
        n = face.normalAt(u, v)
        tip = face.valueAt(u, v) + n * R - FreeCAD.Vector(0, 0, R)
        if j == 0 and k == 0:
            cmds.append(Path.Command("G0", {"X": tip.x, "Y": tip.y, "Z": tip.z + 10.0}))
        cmds.append(Path.Command("G1", {"X": tip.x, "Y": tip.y, "Z": tip.z, "F": 600.0}))
cmds.append(Path.Command("G0", {"Z": cmds[-1].Parameters["Z"] + 10.0}))
op.Gcode = ["%s %s" % (c.Name, " ".join("%s%.6f" % kv for kv in sorted(c.Parameters.items())))
            for c in cmds]
doc.recompute()
assert "Invalid" not in comp.State, comp.State
doc.saveAs(sys.argv[2])
print(len(cmds))
