# SPDX-License-Identifier: LGPL-2.1-or-later
"""Made headless for session_probeop.py: the shop document with a probe operation (argv:
repository root, output document)."""
import shutil
import sys

sys.path.insert(0, sys.argv[1])
from surfcomp.app import cam, documents, fcenv, progress  # noqa: E402

fcenv.import_freecad()
from surfcomp.app.plan_feature import make_measurement_plan  # noqa: E402
from surfcomp.app.probe_op import add_probe_operation  # noqa: E402

cam.setup_workbench()
shutil.copyfile(sys.argv[1] + "/tests/data/documents/shop-0.20.FCStd", sys.argv[2])
doc, _r, _i = documents.open_document(sys.argv[2])
progress.recompute_with_progress(doc, "open")
plan = make_measurement_plan(doc, doc.getObject("Block"), "Face2", Layout="grid", Count="3x3")
progress.recompute_with_progress(doc, "plan")
add_probe_operation(doc.getObject("Job"), plan)
doc.save()
