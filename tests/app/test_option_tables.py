# SPDX-License-Identifier: LGPL-2.1-or-later
"""The compensation's document properties are the option registry's: one property per
option, its tooltip, default and enumeration, and a document object reads back the core's
default Options (the command line: tests/pure/test_option_registry.py)."""

import inspect

from surfcomp.app import features, properties
from surfcomp.core.options import OPTIONS, tooltip
from surfcomp.core.pipeline import Options


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
