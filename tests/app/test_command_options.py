# SPDX-License-Identifier: LGPL-2.1-or-later
"""The app layer's defaults and properties of the commands' own options are the registry's
(surfcomp.core.command_options; the parsers: tests/pure/test_command_options.py): the
region object's Faces and MinCoverage, the moved program's tolerances, the post-processor
of the document routes."""

import dataclasses
import inspect

from surfcomp.core.command_options import COMPENSATE, PROGRAM_MOVE
from surfcomp.core.options import tooltip


def test_the_region_object_has_the_registry_rows():
    from surfcomp.app.region_doc import REGION_PROPERTIES

    rows = {r[1]: r for r in REGION_PROPERTIES}
    assert rows["Faces"] == ("App::PropertyString", "Faces", "Region",
                             "The region: FaceN names separated by commas, or auto (the faces "
                             "the measurements cover)", "auto", 0)
    assert rows["MinCoverage"] == ("App::PropertyFloat", "MinCoverage", "Region",
                                   "Least share of every face's area with measured points near",
                                   0.5, 0)
    for name in ("faces", "min_coverage"):
        o = COMPENSATE[name]
        assert rows[o.prop][3] == tooltip(name, COMPENSATE), name


def test_the_app_defaults_are_the_registry():
    from surfcomp.app import cam_job, document_route, region_docroute, region_route
    from surfcomp.app.program_route import ProgramJob

    fields = {f.name: f.default for f in dataclasses.fields(ProgramJob)}
    for name in ("blend", "tolerance", "segment_length", "decimals"):
        assert fields[name] == PROGRAM_MOVE[name].default, name
    assert (fields["tolerance"], fields["blend"], fields["segment_length"]) == (5e-4, 1.0, 2.0)
    assert inspect.signature(region_route.run_region).parameters["min_coverage"].default == \
        COMPENSATE["min_coverage"].default == 0.5
    for func in (document_route.run_document_job, region_docroute.run_region_document):
        params = inspect.signature(func).parameters
        assert (params["post"].default, params["post_args"].default) == \
            (COMPENSATE["post"].default, COMPENSATE["post_args"].default), func.__name__
    params = inspect.signature(cam_job.post_process).parameters
    assert (params["post"].default, params["args"].default) == \
        (COMPENSATE["post"].default, COMPENSATE["post_args"].default)


def test_the_region_field_radius_is_the_one_the_faces_help_gives():
    """compensate --faces' help gives the field radius's default from the limits module;
    the region route computes it from the same names."""
    from surfcomp.app import region
    from surfcomp.core import limits

    assert region.FIELD_SHARE is limits.FIELD_SHARE
    assert region.FIELD_SPACINGS is limits.FIELD_SPACINGS
