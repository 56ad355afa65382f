# SPDX-License-Identifier: LGPL-2.1-or-later
"""The example's finishing Job, before and after the compensation replaces the nominal: one
document for the tests of Path's regeneration (test_path_regen.py) and of the direct program
route (test_direct_program.py), built once a session (the ``cam_example`` fixture of
tests/app/conftest.py; three Path computations, about 35 s).

The Job: a 3D Surface operation (6 mm ball end mill, line pattern, 3 mm step-over, 1 mm
samples, every sample kept, mesh deflection 1 um) on the example's nominal face; the
compensation of the example measurements (refine 1) replaces the nominal, the document
recomputes and the operation regenerates on the corrected face. Programs posted with 4
decimals: FINISH.ngc (nominal), DRESSUP.ngc (the nominal operation under a surface
correction dressup, deleted again before the replace), CAM.ngc (regenerated).
"""

from types import SimpleNamespace

import FreeCAD
import Part

from surfcomp.app import cam, cam_job, features, replace, reports
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP

R = 3.0                       # ball radius (mm)
POST_ARGS = "--no-show-editor --no-header --precision=4"


def settled_job(doc, nom, deflection):
    """A Job on ``nom`` with its model clone meshed as the operation will mesh it.

    Path's stock follows the model clones' bounding boxes, which become tight once the
    clone is meshed (OCCT then bounds the triangulation): meshing it and settling the stock
    before the operation exists makes the compensation the only change of the program (and
    the operation is computed once, not again for the stock)."""
    job = cam_job.create_job(doc, [nom])
    clone = cam_job.model_clone(job, nom)
    clone.Shape.tessellate(deflection)
    clone.touch()
    doc.recompute()
    return job


def with_dressup(doc, job, comp, tmp, found):
    """Post the Job with a surface correction dressup on its operation (DRESSUP.ngc); the
    dressup's results and whether the operation's path stayed as it was go into ``found``;
    the dressup is deleted again."""
    from surfcomp.app import dressup_surface

    op = [o for o in job.Operations.Group if o.Name.startswith("Surface")][0]
    before = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
    d = dressup_surface.Create(op, comp)
    doc.recompute()
    found.update(state=list(d.State), radius=float(d.BallRadius.Value),
                 moved=d.MovedMoves, max_move=float(d.MaxMove.Value),
                 contact=d.ContactPoints, ops=[o.Name for o in job.Operations.Group],
                 op_kept=[(c.Name, dict(c.Parameters)) for c in op.Path.Commands] == before,
                 touched="Touched" in op.State)
    (tmp / "DRESSUP.ngc").write_text(cam_job.post_process(job, "linuxcnc", POST_ARGS))
    # without a base: an empty path and none of those figures kept
    d.Base = None
    d.recompute()
    found.update(no_base=[len(d.Path.Commands), d.MovedMoves, float(d.MaxMove.Value),
                          d.ContactPoints])
    d.Base = op                # deleting it puts its base back into the Job
    d.Proxy.onDelete(d, None)
    doc.removeObject(d.Name)
    doc.recompute()


def build(tmp, deflection=0.001):
    """The example's Job before and after the replace (the document stays open):
    ``doc, nom, comp, job, op``; ``before``/``after`` (cutter locations, posted G-code,
    states, the nominal's shape, the replace's links); ``finish``, ``dressup``, ``regen``
    (paths of FINISH.ngc, DRESSUP.ngc, CAM.ngc in ``tmp``), ``corrected`` (the corrected
    core surface) and ``found`` (the dressup's results, :func:`with_dressup`)."""
    cam.setup_workbench()
    doc = FreeCAD.newDocument("camexample")
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    doc.recompute()
    job = settled_job(doc, nom, deflection)
    tc = cam_job.ball_end_tool_controller(job, 2 * R)
    op = cam_job.surface_operation(job, nom, ["Face1"], tc, step_over=50.0, sample_interval=1.0,
                                   linear_deflection=deflection)
    m = features.make_measurement(doc, EXAMPLE_CSV)
    comp = features.make_compensation(doc, nom, "Face1", m)
    comp.Refine = 1          # fewer knots: OCCT meshes the corrected face 7x faster
    doc.recompute()
    before = {"cl": cam_job.cutter_locations(op),
              "gcode": cam_job.post_process(job, "linuxcnc", POST_ARGS),
              "state": list(op.State), "nominal": nom.Shape.copy()}
    finish = tmp / "FINISH.ngc"
    finish.write_text(before["gcode"])
    found = {}
    with_dressup(doc, job, comp, tmp, found)
    links = replace.replace(doc, comp)
    doc.recompute()
    after = {"cl": cam_job.cutter_locations(op),
             "gcode": cam_job.post_process(job, "linuxcnc", POST_ARGS),
             "invalid": [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State],
             "links": links}
    regen = tmp / "CAM.ngc"
    regen.write_text(after["gcode"])
    return SimpleNamespace(doc=doc, nom=nom, comp=comp, job=job, op=op, before=before,
                           after=after, tmp=tmp, finish=finish, dressup=tmp / "DRESSUP.ngc",
                           regen=regen, corrected=reports.corrected_surface(comp), found=found)
