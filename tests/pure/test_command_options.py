# SPDX-License-Identifier: LGPL-2.1-or-later
"""The registry's tables of the commands' own options (surfcomp.core.command_options:
simulate's loop, the axis error file, gcode, compensate --program, compensate's region and
post-processing; and option_tables.SIM_PLAN, simulate's plan options) are the one place
those options are defined: the parsers of simulate, gcode and compensate read their flags,
defaults, choices and help from them, the checks their domains, and the core's and io's
defaults agree with them (the region object's properties: tests/app/test_command_options.py)."""

import inspect

import pytest

from surfcomp.cli import build_parser
from surfcomp.cli.option_flags import flag
from surfcomp.core.command_options import (
    AXIS_FILE,
    COMPENSATE,
    GCODE,
    PRESET_SET,
    PROGRAM_MOVE,
    SIMULATE,
)
from surfcomp.core.option_tables import PLAN, SIM_PLAN, TABLES, find
from surfcomp.core.options import cli_help
from surfcomp.errors import InputError
from tests.pure.test_option_tables import _actions, _agrees


def _simulate_args(*extra):
    return build_parser("simulate").parse_args(["simulate", "n.step", *extra])


def test_simulate_takes_its_loop_from_the_registry():
    acts = _actions("simulate")
    for name, o in SIMULATE.items():
        # a preset's option is unset when not given: the preset's value, else the default
        _agrees(acts[o.flag], name, SIMULATE, default=name not in PRESET_SET)
        assert acts[o.flag].default == (None if name in PRESET_SET else o.default), name
    assert acts["--grid"].help == ("measurement grid, uniform in the face parameters, at most "
                                   "800 x 800 (default 45x45, Werner 2022, or the preset's)")
    assert acts["--stock"].help.endswith("(default 0.3, or the preset's)")
    assert (acts["--margin"].type, acts["--replicas"].type, acts["--grid"].type) == \
        (float, int, None)
    for name in AXIS_FILE:
        _agrees(acts[AXIS_FILE[name].flag], name, AXIS_FILE)
    assert acts["--axis-units"].choices == ("mm", "um", "in")
    assert acts["--max-error"].help.endswith("(default 1, as for gcode)")


def test_simulate_takes_the_plan_records_for_its_plan_options():
    acts = _actions("simulate")
    for name, o in SIM_PLAN.items():
        _agrees(acts[o.flag], name, SIM_PLAN)
        assert acts[o.flag].default is None, name              # unset: the grid nodes
    # the same options as plan's, under simulate's attributes
    for name in ("layout", "count", "points"):
        mine, plans = SIM_PLAN[name], PLAN[name]
        assert (mine.flag, mine.type, mine.choices, mine.metavar, mine.low, mine.high) == \
            (plans.flag, plans.type, plans.choices, plans.metavar, plans.low, plans.high)
        assert acts[mine.flag].dest == "plan_" + name
    assert acts["--layout"].choices == ("grid", "xy", "adaptive", "uniform")
    assert cli_help("layout", SIM_PLAN) == ("measure at points planned on the face: grid or "
                                            "xy (--count UxV), adaptive or uniform "
                                            "(--points N)")
    assert (acts["--points"].type, acts["--compare-layouts"].type) == (int, int)


def test_gcode_takes_its_options_from_the_registry():
    acts = _actions("gcode")
    for name, o in GCODE.items():
        _agrees(acts[o.flag], name, GCODE)
    assert acts["--units"].dest == "units" and acts["--units"].choices == ("mm", "um", "in")
    assert acts["--model"].choices == ("linear", "quadratic", "auto")
    assert acts["--reference"].help.endswith("(default 0,0,0)")
    assert acts["--tolerance"].help.endswith("(default 0.0001, > 0)")
    assert acts["--segment-length"].help.endswith(
        "at least 0.001 mm, and at most 10000000 segments in all (default 2)")
    # the axis file as simulate reads it, under gcode's flag of the units
    for name, mine in (("axis_units", "units"), ("max_error", "max_error"),
                       ("reference", "reference")):
        assert (GCODE[mine].default, GCODE[mine].choices) == \
            (AXIS_FILE[name].default, AXIS_FILE[name].choices), name


def test_gcode_defaults_are_the_io_and_core_defaults():
    from surfcomp.core.axis import axis_errors, moves
    from surfcomp.io.gcode.stream import compensate_gcode

    params = inspect.signature(compensate_gcode).parameters
    for name in ("segment_length", "tolerance", "arc_tolerance", "decimals", "start"):
        assert params[name].default == GCODE[name].default, name
    assert inspect.signature(axis_errors.fit_axis_errors).parameters["model"].default == \
        GCODE["model"].default
    assert axis_errors.MODEL_CHOICES == GCODE["model"].choices
    assert (moves.MIN_SEGMENT_LENGTH, moves.MAX_SEGMENTS) == \
        (GCODE["segment_length"].low, 10_000_000)


def test_compensate_takes_the_program_region_and_post_options_from_the_registry():
    acts = _actions("compensate")
    for table in (PROGRAM_MOVE, COMPENSATE):
        for name, o in table.items():
            _agrees(acts[o.flag], name, table)
    assert (acts["--tolerance"].default, acts["--blend"].default) == (5e-4, 1.0)
    assert acts["--min-coverage"].help == ("with --faces: least share of every face's area "
                                           "with measured points near (default 0.5)")
    assert acts["--post"].default == "linuxcnc"
    from surfcomp.io.gcode.offset_stream import offset_commands

    params = inspect.signature(offset_commands).parameters
    for name in ("tolerance", "segment_length"):
        assert params[name].default == PROGRAM_MOVE[name].default, name


@pytest.mark.parametrize("value", ["-0.01", "1.01", "nan"])
def test_the_region_refuses_a_coverage_outside_the_registry_domain(value):
    from surfcomp.cli.region import run_region_command

    args = build_parser("compensate").parse_args(
        ["compensate", "n.step", "m.csv", "--faces", "auto", "-o", "out.step",
         "--min-coverage", value])
    with pytest.raises(InputError) as exc:
        run_region_command(args)
    assert str(exc.value) == "--min-coverage must be between 0 and 1 (got %s)" % value


def test_the_loop_without_a_preset_runs_the_registry_defaults():
    from surfcomp.cli.simulate import loop_value
    from surfcomp.core.simulation.presets import get_preset

    args = _simulate_args()
    assert [loop_value(args, None, n) for n in ("grid", "replicas", "between", "stock")] == \
        [(45, 45), 4, 2, 0.3]
    werner = get_preset("werner2022")
    assert [loop_value(args, werner, n) for n in ("grid", "replicas", "between")] == \
        [tuple(werner.grid), werner.replicas, werner.between]
    given = _simulate_args("--grid", "7x9", "--replicas", "2", "--between", "3")
    assert [loop_value(given, werner, n) for n in ("grid", "replicas", "between")] == \
        [(7, 9), 2, 3]
    assert (args.margin, args.seed, args.methods) == (0.02, 0, "none,offset,raw,filtered,mirror")


def test_the_core_defaults_are_the_registry():
    from surfcomp.core.simulation import process_model
    from surfcomp.core.simulation import simulate as sim
    from surfcomp.io.axis_csv import read_axis_errors

    params = inspect.signature(sim.simulate).parameters
    assert params["grid"].default == tuple(int(n) for n in SIMULATE["grid"].default.split("x"))
    for name in ("replicas", "seed", "margin", "between"):
        assert params[name].default == SIMULATE[name].default, name
    assert process_model.DEFAULT_STOCK == process_model.MachiningModel().stock == \
        SIMULATE["stock"].default
    assert set(SIMULATE["methods"].default.split(",")) == set(sim.SIM_METHODS)
    assert (sim.MAX_GRID, sim.MAX_REPLICAS) == (800, SIMULATE["replicas"].high)
    assert inspect.signature(read_axis_errors).parameters["units"].default == \
        AXIS_FILE["axis_units"].default


@pytest.mark.parametrize("option, value, message", [
    ("--margin", "0.5", "--margin 0.5: expected a fraction >= 0 and < 0.5"),
    ("--margin", "-0.001", "--margin -0.001: expected a fraction >= 0 and < 0.5"),
    ("--stock", "-0.01", "--stock -0.01: expected a finite allowance >= 0 mm"),
    ("--between", "0", "--between 0: expected a whole number >= 1"),
    ("--seed", "-1", "--seed -1: expected a whole number >= 0"),
    ("--replicas", "1001", "--replicas 1001: expected at most 1000 (the mirror paper "
                           "machines 4 parts per method)"),
])
def test_the_loop_refuses_just_outside_the_registry_domain(option, value, message):
    from surfcomp.cli.simulate import check_loop_options

    with pytest.raises(InputError) as exc:
        check_loop_options(_simulate_args(option, value))
    assert str(exc.value) == message
    # the domain's own ends are taken
    check_loop_options(_simulate_args("--margin", "0", "--stock", "0", "--between", "1",
                                      "--seed", "0", "--replicas", "1000"))
    check_loop_options(_simulate_args("--margin", "0.499", "--replicas", "1"))


def test_every_new_name_maps_to_its_flag():
    for key in ("simulate", "sim_plan", "axis_file", "gcode", "program_move", "compensate"):
        for name, o in TABLES[key].items():
            if find(name) is o:
                assert flag(name) == o.flag, name
    # names the earlier tables hold keep their own record: stock is the compensation's
    assert find("stock").prop == "Stock" and find("stock", ("simulate",)) is SIMULATE["stock"]
    assert (flag("compare_layouts"), flag("margin"), flag("axis_units")) == \
        ("--compare-layouts", "--margin", "--axis-units")
