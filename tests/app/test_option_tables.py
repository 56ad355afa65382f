# SPDX-License-Identifier: LGPL-2.1-or-later
"""The compensation's document properties are the option registry's: one property per
option, its tooltip, default and enumeration, and a document object reads back the core's
default Options (the command line: tests/pure/test_option_registry.py)."""

import dataclasses
import inspect

from surfcomp.app import features, properties
from surfcomp.core.compensation.pipeline import Options
from surfcomp.core.options import OPTIONS, tooltip


def test_every_option_is_a_compensation_property_with_the_registry_row():
    rows = {r[1]: r for r in properties.COMPENSATION_PROPERTIES}
    for name, o in OPTIONS.items():
        typ, prop, group, tip, default, mode = rows[o.prop]
        assert (group, mode, tip) == ("Compensation", 0, tooltip(name)), name
        if o.choices is not None:
            assert typ == "App::PropertyEnumeration" and default == list(o.choices), name
        elif o.default is None:
            assert default in (0.0, ""), name          # unset: 0 or empty
        else:
            assert default == o.default and type(default) is o.type, name


def test_a_new_object_holds_the_registry_defaults(fresh_doc):
    obj = fresh_doc.addObject("Part::FeaturePython", "Compensation")
    features.CompensationFeature(obj)
    for name, o in OPTIONS.items():
        assert obj.getDocumentationOfProperty(o.prop) == tooltip(name), name
        if o.choices is not None:
            assert obj.getEnumerationsOfProperty(o.prop) == list(o.choices), name
    obj.Method = OPTIONS["method"].default        # make_compensation sets the method
    assert features.options_of(obj) == Options(stock=0.0, context="document")


def test_the_app_functions_default_to_the_registry():
    from surfcomp.app import precheck, region_route

    params = inspect.signature(features.make_compensation).parameters
    for name in ("method", "mask_size", "edge"):
        assert params[name].default == OPTIONS[name].default, name
    params = inspect.signature(region_route.run_region).parameters
    for name in ("method", "mask_size", "mask_kind", "sigma", "max_offset", "smoothing"):
        assert params[name].default == OPTIONS[name].default, name
    params = inspect.signature(precheck.check_on_face).parameters
    assert params["max_offset"].default == OPTIONS["max_offset"].default


def test_options_stored_on_an_object_read_back_the_same(fresh_doc):
    """store_options (the document route) writes every option, and options_of reads the
    same Options back: a non-default value of each survives the property round trip (the
    document route left layout, smoothing and tip radius at their defaults before)."""
    obj = fresh_doc.addObject("Part::FeaturePython", "Compensation")
    features.CompensationFeature(obj)
    given = Options(method="mirror", mask_size=7, weights=[[1, 2, 1], [2, 4, 2], [1, 2, 1]],
                    mask_kind="gaussian", sigma=1.5, edge="nearest", stock=0.3,
                    accept_stock=True, max_offset=0.4, flip_normals=True, refine=2, lean=False,
                    tip_radius=0.5, layout="scattered", smoothing=2.5)
    for name, o in OPTIONS.items():            # every option differs from its default
        assert getattr(given, name) != o.default, name
    properties.store_options(obj, given)
    back = features.options_of(obj)
    assert obj.Weights == "1 2 1; 2 4 2; 1 2 1"
    assert back == dataclasses.replace(given, weights="1 2 1; 2 4 2; 1 2 1", context="document")
    properties.store_options(obj, Options(stock=0.3))
    assert features.options_of(obj) == Options(stock=0.3, context="document")
    assert (obj.Sigma, obj.Smoothing.Value, obj.Weights) == (0.0, 0.0, "")   # unset: 0, empty


def test_the_other_objects_properties_are_the_registry_rows(fresh_doc):
    """The measurement's Align* properties, the plan's settings and the probe operation's
    are rows of the registry's tables (surfcomp.core.option_tables): a new object holds the
    property, its tooltip, its default and its enumeration; the names stay the contract."""
    from surfcomp.app import plan_feature, probe_op
    from surfcomp.core.option_tables import ALIGN, INPUTS, PLAN, PROGRAM

    assert [ALIGN[n].prop for n in ALIGN] == ["AlignMethod", "AlignFaces", "AlignDof",
                                              "AlignRps", "AlignTransform"]
    checked = 0
    for rows, table, names in (
            (properties.MEASUREMENT_PROPERTIES, ALIGN, tuple(ALIGN)),
            (properties.COMPENSATION_PROPERTIES, INPUTS, ("face",)),
            (plan_feature.PLAN_PROPERTIES, PLAN, ("layout", "count", "points", "tip_radius",
                                                  "edge_margin", "max_tilt", "stand_off",
                                                  "clearance")),
            (probe_op.PROBE_OP_PROPERTIES, PROGRAM, ("work_offset", "overtravel", "feed",
                                                     "touch_feed", "log_file"))):
        by_prop = {r[1]: r for r in rows}
        for name in names:
            o = table[name]
            typ, _prop, _group, tip, default, mode = by_prop[o.prop]
            assert (tip, mode) == (tooltip(name, table), 0), name
            if o.choices is not None:
                assert typ == "App::PropertyEnumeration" and default == list(o.choices), name
            elif typ.endswith("List"):
                assert default is None, name
            else:
                unset = o.stored if o.stored is not None else o.type()    # 0 or empty
                assert default == (o.default if o.default is not None else unset), name
            checked += 1
    assert checked == 19
    meas = fresh_doc.addObject("Part::FeaturePython", "Measurement")
    features.MeasurementFeature(meas)
    for name, o in ALIGN.items():
        assert meas.getDocumentationOfProperty(o.prop) == tooltip(name, ALIGN), name
    assert meas.getEnumerationsOfProperty("AlignMethod") == list(ALIGN["align"].choices)
    assert (meas.AlignMethod, meas.AlignDof, meas.AlignFaces) == ("none", "all", "")


def test_document_warnings_name_the_properties():
    """A warning that names options (a Note) is kept in a document with the options named
    as its properties (the command line shows flags, the panels labels)."""
    from surfcomp.errors import note

    text = note("bring them near with ", ("transform",), ", or name datum faces with ",
                ("align_faces",), " (a transform)")
    assert properties.property_text(text) == \
        "bring them near with AlignTransform, or name datum faces with AlignFaces (a transform)"
    assert properties.property_text("plain") == "plain"
