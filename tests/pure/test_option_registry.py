# SPDX-License-Identifier: LGPL-2.1-or-later
"""The option registry (surfcomp.core.options) is the one place an option of the
compensation is defined: the core's Options, its validation and the command line's parsers
read their defaults, domains and help from it (the property tables and the filter panel:
tests/app/test_option_tables.py, tests/gui/test_filter.py)."""

import dataclasses
import subprocess
import sys

import pytest

from surfcomp.cli import build_parser
from surfcomp.cli.option_flags import shown
from surfcomp.core import limits
from surfcomp.core.compensation import corrected, filters, pipeline
from surfcomp.core.compensation.pipeline import Options
from surfcomp.core.options import OPTIONS, cli_help, tooltip
from surfcomp.errors import InputError
from tests.conftest import ROOT


def _actions(command):
    sub = next(a for a in build_parser(command)._actions if a.choices and command in a.choices)
    return {a.option_strings[0] if a.option_strings else a.dest: a
            for a in sub.choices[command]._actions}


def test_the_registry_imports_without_numpy():
    code = ("import sys; sys.modules['numpy'] = sys.modules['scipy'] = None; "
            "sys.path.insert(0, %r); from surfcomp.core.options import OPTIONS; "
            "print(len(OPTIONS))" % ROOT)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout) == len(OPTIONS) == 15


def test_every_field_of_options_is_in_the_registry_with_its_default():
    names = {f.name for f in dataclasses.fields(Options)} - {"context"}
    assert names == set(OPTIONS)
    for f in dataclasses.fields(Options):
        if f.name in OPTIONS:
            assert f.default == OPTIONS[f.name].default, f.name
    assert (Options().mask_size, Options().refine) == (5, 4)       # Werner 2022; 4 spans
    assert filters.WERNER_MASK_SIZE == 5 and corrected.DEFAULT_REFINE == 4


@pytest.mark.parametrize("command", ["compensate", "inspect"])
def test_the_job_parsers_take_flag_default_choices_and_help_from_the_registry(command):
    acts = _actions(command)
    for name, o in OPTIONS.items():
        if o.flag is None or command == "inspect" and o.flag not in acts:
            continue
        a = acts[o.flag]
        assert a.help == cli_help(name), name
        assert a.default == (False if o.type is bool else o.default), name
        assert a.choices == o.choices, name
    # inspect builds no face: the method and surface options are compensate's only
    assert "--max-offset" in acts and "--mask" in acts
    assert ("--method" in acts, "--refine" in acts) == ((command == "compensate",) * 2)


def test_the_parsed_defaults_are_the_core_options():
    args = build_parser("compensate").parse_args(["compensate", "n.step", "m.csv"])
    from surfcomp.cli.common import options_from_args

    assert options_from_args(args) == Options()
    args = build_parser("compensate").parse_args(
        ["compensate", "n.step", "m.csv", "--mask", "7", "--mask-kind", "gaussian",
         "--sigma", "1.5", "--refine", "2", "--edge", "nearest", "--accept-stock"])
    o = options_from_args(args)
    assert (o.mask_size, o.mask_kind, o.sigma, o.refine, o.edge, o.accept_stock) == \
        (7, "gaussian", 1.5, 2, "nearest", True)


def test_simulate_parser_shares_the_filter_options():
    acts = _actions("simulate")
    for name in ("mask_kind", "edge", "refine"):
        o = OPTIONS[name]
        assert acts[o.flag].default == o.default and acts[o.flag].choices == o.choices
        if name != "mask_kind":         # (whose help speaks of --weights, which simulate lacks)
            assert acts[o.flag].help == cli_help(name)
    assert acts["--mask"].default == "5"            # a list of sizes, the registry's default
    assert acts["--mask-kind"].help.endswith("(default box)")


def test_help_names_other_options_as_each_front_end_does():
    assert "needs --stock" in cli_help("method") and "needs Stock" in tooltip("method")
    assert cli_help("mask_size").endswith("(default 5, as in Werner 2022)")
    assert tooltip("sigma").endswith("(0: MaskSize / 4)")
    assert cli_help("sigma").endswith("(default --mask / 4)")
    assert tooltip("weights").endswith("(empty: MaskKind and MaskSize)")
    assert "0.1 um / 1 um limits" in tooltip("refine")     # from the limits module
    assert "scipy.ndimage's 'mirror'" in cli_help("edge")  # reflect is ndimage's mirror


@pytest.mark.parametrize("name", sorted(n for n, o in OPTIONS.items() if o.low is not None))
def test_validation_refuses_just_outside_the_registry_domain(name):
    o = OPTIONS[name]
    ok = {"mask_size": 201, "refine": 16}.get(name, o.high)
    Options(**{name: ok}).validate()
    Options(**{name: o.low}).validate()
    step = 1 if o.type is int else 1e-9 * max(1.0, abs(o.high))
    fraction = (o.low + 0.5,) if o.type is int else ()     # whole numbers only
    for bad in (o.low - step, o.high + step, float("nan")) + fraction:
        with pytest.raises(InputError) as exc:
            Options(**{name: bad}).validate()
        # the core names the option, the command line shows its flag
        assert exc.value.message.startswith(name + " ") and o.prop in exc.value.message
        assert exc.value.options == (name,)
        assert shown(exc.value).startswith(o.flag + " ")


@pytest.mark.parametrize("name", sorted(n for n, o in OPTIONS.items() if o.choices))
def test_validation_refuses_a_value_outside_the_choices(name):
    for good in OPTIONS[name].choices:
        Options(**{name: good}, stock=0.1).validate()
    with pytest.raises(InputError) as exc:
        Options(**{name: "bogus"}).validate()
    assert exc.value.message == "%s 'bogus': expected one of %s" % (
        name, ", ".join(OPTIONS[name].choices))
    assert shown(exc.value) == "%s 'bogus': expected one of %s" % (
        OPTIONS[name].flag, ", ".join(OPTIONS[name].choices))


def test_one_name_per_limit():
    """The corrected face's limits are one value each, used by the construction and by the
    pipeline's warnings (they had two names each)."""
    assert corrected.ACCEPT_TOL is limits.ACCEPT_TOL == 1e-4
    assert corrected.OVERSHOOT_TOL is limits.OVERSHOOT_TOL == 1e-3
    assert pipeline.ACCEPT_TOL is limits.ACCEPT_TOL
    for old in ("MISS_WARNING", "OVERSHOOT_WARNING"):
        assert not hasattr(pipeline, old)
    assert filters.MAX_MASK_SIZE == OPTIONS["mask_size"].high == OPTIONS["sigma"].high == 201


def test_the_job_file_checks_each_option_by_its_registry_type():
    """The JSON job file (the other parser of the options) knows every option by its name,
    refuses a value of the wrong type with what was expected, and takes null where the
    option may be unset."""
    from surfcomp.io.jobfile import KEY_TYPES, NULLABLE

    expected = {int: "a whole number", bool: "true or false", str: "a non-empty string"}
    for name, o in OPTIONS.items():
        what, ok = KEY_TYPES[name]
        assert (name in NULLABLE) == o.optional, name
        if name == "weights":
            assert ok("1 2 1; 2 4 2; 1 2 1") and not ok({})
        elif o.type is float:
            assert what == ("a finite number or null" if o.optional else "a finite number")
            assert ok(o.high) and not ok(float("nan")) and not ok(True)
        else:
            assert what == expected[o.type], name
            assert ok(o.default) and not ok(None if o.type is bool else 2.5)


def test_the_core_functions_default_to_the_registry():
    """Functions below Options keep their own keyword defaults; they must be the
    registry's (the issue's make_mask(5) and --refine 4 copies)."""
    import inspect

    from surfcomp.core.compensation import methods, plausibility, region_field
    from surfcomp.core.simulation import simulate

    def defaults(fn):
        return {k: p.default for k, p in inspect.signature(fn).parameters.items()}

    reg = {n: o.default for n, o in OPTIONS.items()}
    assert defaults(filters.make_mask)["size"] == reg["mask_size"]
    assert defaults(filters.make_mask)["kind"] == reg["mask_kind"]
    assert defaults(filters.mask_filter)["edge"] == reg["edge"]
    got = defaults(methods.compute_correction)
    assert (got["method"], got["edge"]) == (reg["method"], reg["edge"])
    got = defaults(region_field.mask_filter_3d)
    assert (got["mask_size"], got["kind"]) == (reg["mask_size"], reg["mask_kind"])
    got = defaults(simulate.method_specs)
    assert (got["mask_kind"], got["edge"]) == (reg["mask_kind"], reg["edge"])
    assert got["masks"] == (reg["mask_size"],)
    assert plausibility.DEFAULT_MAX_OFFSET == reg["max_offset"] == 1.0
    assert defaults(corrected.construct)["refine"] == reg["refine"]


@pytest.mark.parametrize("table, name, flag, low, high", [
    ("compensate", "touches", "--touches", 1, limits.MAX_TOUCHES),
    ("gcode", "decimals", "--decimals", 0, 9),
    ("program", "decimals", "--decimals", 3, 9),
])
def test_ranges_enforced_elsewhere_are_in_the_registry_and_the_help(table, name, flag, low,
                                                                   high):
    """--touches (1 to 9, checked where a log is joined to its plan) and the two
    --decimals (0 to 9 for gcode, 3 to 9 for --program) were enforced but their ranges were
    written in neither the registry nor the help."""
    from surfcomp.cli.options import check_range
    from surfcomp.core.command_options import GCODE, PROGRAM_MOVE
    from surfcomp.core.option_tables import INPUTS

    tables = {"compensate": INPUTS, "gcode": GCODE, "program": PROGRAM_MOVE}
    o = tables[table][name]
    assert (o.flag, o.low, o.high) == (flag, low, high)
    assert cli_help(name, tables[table]).endswith("%d to %d)" % (low, high))
    check_range(o, low)
    check_range(o, high)
    with pytest.raises(InputError, match=r"^%s %d: expected %d to %d$" % (flag, high + 1, low,
                                                                          high)):
        check_range(o, high + 1)
