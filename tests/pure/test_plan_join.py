# SPDX-License-Identifier: LGPL-2.1-or-later
"""A plan file read, and a probe log joined to it: in order, the tip radius along the
plan's normals, a log that does not fit refused at its first line that does not."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.pipeline import Options
from surfcomp.errors import InputError, MeasurementFileError
from surfcomp.io.plan_join import join_plan, read_plan
from surfcomp.io.readers import read_any

R = 1.0


def write_plan(path, n=6):
    t = np.linspace(0, 1, n)
    P = np.stack([10 * t, 5 * t ** 2, 2 + t], 1)
    N = np.stack([0.3 * t, -0.2 * np.ones(n), np.ones(n)], 1)
    N /= np.linalg.norm(N, axis=1)[:, None]
    path.write_text("# plan\nid,x_nom,y_nom,z_nom,i,j,k\n" + "".join(
        "Q%d,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f\n" % ((k,) + tuple(P[k]) + tuple(N[k]))
        for k in range(n)))
    return P, N


def write_log(path, centres):
    path.write_text("".join("%.6f %.6f %.6f 0.000000 0.000000 0.000000 0.000000 0.000000 "
                            "0.000000\n" % tuple(c) for c in centres))


def test_plan_file_and_join(tmp_path):
    P, N = write_plan(tmp_path / "plan.csv")
    plan = read_plan(str(tmp_path / "plan.csv"))
    assert plan.ids == ["Q%d" % k for k in range(6)] and list(plan.lines) == list(range(3, 9))
    assert_allclose(plan.points, P, atol=1e-9)
    d = np.array([0.01, -0.02, 0.0, 0.005, 0.03, -0.01])
    write_log(tmp_path / "probe.log", P + (R + d)[:, None] * N)
    ms = join_plan(plan, read_any(str(tmp_path / "probe.log")), Options(tip_radius=R))
    assert ms.kind() == "nominal+measured+normal" and ms.deviation is None
    assert ms.source == str(tmp_path / "probe.log") and ms.ids == plan.ids
    # the pipeline's deviation of such a set: (c - p) . n - R
    dev = np.einsum("ij,ij->i", ms.measured - ms.nominal, ms.normal) - R
    assert_allclose(dev, d, atol=1e-6)


def test_second_touch_log_takes_the_last_line_of_each_point(tmp_path):
    P, N = write_plan(tmp_path / "plan.csv")
    plan = read_plan(str(tmp_path / "plan.csv"))
    first, second = P + (R + 0.012) * N, P + (R + 0.010) * N
    write_log(tmp_path / "probe.log", np.stack([first, second], 1).reshape(-1, 3))
    ms = join_plan(plan, read_any(str(tmp_path / "probe.log")), Options(tip_radius=R), 2)
    assert_allclose(ms.measured, second, atol=1e-6)
    assert list(ms.lines) == [2, 4, 6, 8, 10, 12]
    with pytest.raises(MeasurementFileError) as err:     # read as one touch per point
        join_plan(plan, read_any(str(tmp_path / "probe.log")), Options(tip_radius=R))
    assert str(err.value).startswith("%s:7: probe line 7 has no planned point: the plan "
                                     % (tmp_path / "probe.log"))


def test_logs_that_do_not_fit_are_named_at_their_first_line(tmp_path):
    P, N = write_plan(tmp_path / "plan.csv")
    plan = read_plan(str(tmp_path / "plan.csv"))
    log = tmp_path / "probe.log"
    centres = P + (R + 0.01) * N
    write_log(log, centres[:4])
    with pytest.raises(MeasurementFileError) as err:
        join_plan(plan, read_any(str(log)), Options(tip_radius=R))
    assert str(err.value).startswith("%s:7: planned point Q4 has no probe line: the log %s "
                                     "holds 4 lines, expected 6" % (tmp_path / "plan.csv", log))
    # lines 3 and 5 swapped: line 3 is 2 mm from its planned point Q2
    write_log(log, centres[[0, 1, 4, 3, 2, 5]])
    with pytest.raises(MeasurementFileError) as err:
        join_plan(plan, read_any(str(log)), Options(tip_radius=R, max_offset=1.0))
    text = str(err.value)
    assert text.startswith("%s:3: probe line 3 (" % log)
    assert "from its planned point Q2 (%s:5," % (tmp_path / "plan.csv") in text
    assert "expected at most max_offset 1 mm (2 line(s) do not fit)" in text
    # the wrong tip radius puts every line R off
    write_log(log, centres)
    with pytest.raises(MeasurementFileError, match=r"probe.log:1: probe line 1 .* lies 1.0100"):
        join_plan(plan, read_any(str(log)), Options(tip_radius=0.0, max_offset=0.5))
    with pytest.raises(InputError, match="holds nominal points"):
        join_plan(plan, _table(tmp_path, P, N), Options())


def _table(tmp_path, P, N):
    path = tmp_path / "cmm.csv"
    path.write_text("x_nom,y_nom,z_nom,i,j,k,dev\n" + "".join(
        "%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,0.0\n" % (tuple(p) + tuple(n)) for p, n in zip(P, N)))
    return read_any(str(path))


def test_plan_without_normals_is_refused(tmp_path):
    path = tmp_path / "plan.csv"
    path.write_text("id,x_nom,y_nom,z_nom\nA,0,0,0\n")
    with pytest.raises(MeasurementFileError,
                       match=r"plan.csv:1: .*no normal \(i j k\) \(expected a plan: id, nominal"):
        read_plan(str(path))


def test_fanuc_dprnt_output_reads_as_a_probe_log(tmp_path):
    """The Fanuc dialect's DPRNT[#5061[44]*#5062[44]*#5063[44]*0*0*0*0*0*0] lines (leading
    zeros printed as blanks, 4 decimals) are read as the LinuxCNC log's layout."""
    P, N = write_plan(tmp_path / "plan.csv")
    plan = read_plan(str(tmp_path / "plan.csv"))
    d = np.array([0.004, -0.002, 0.0, 0.001, 0.003, -0.001])
    centres = P + (R + d)[:, None] * N
    log = tmp_path / "dprnt.txt"
    log.write_text("".join("%9.4f%10.4f%10.4f 0 0 0 0 0 0\n" % tuple(c) for c in centres))
    ms = read_any(str(log))
    assert ms.tip_centres and ms.measured.shape == (6, 3)
    joined = join_plan(plan, ms, Options(tip_radius=R))
    dev = np.einsum("ij,ij->i", joined.measured - joined.nominal, joined.normal) - R
    assert_allclose(dev, d, atol=1e-4)       # 4 decimals


def test_an_inch_log_is_joined_to_the_plan_in_mm(tmp_path):
    """``units`` is the log's (a program posted in G20 logs inches): the plan stays in mm,
    as ``plan`` writes it; it used to be scaled by 25.4 with the log, and every line was
    refused as 'not from this plan's program'."""
    from surfcomp.app.file_route import Job
    from surfcomp.io.readers import read_measured

    P, N = write_plan(tmp_path / "plan.csv")
    d = np.array([0.01, -0.02, 0.0, 0.005, 0.03, -0.01])
    write_log(tmp_path / "probe.log", (P + (R + d)[:, None] * N) / 25.4)
    job = Job(nominal="n.step", measurements=str(tmp_path / "probe.log"), units="in",
              plan=str(tmp_path / "plan.csv"), options=Options(tip_radius=R))
    ms = read_measured(job)
    assert ms.units == "in"
    assert_allclose(ms.nominal, P, atol=1e-9)
    assert_allclose(np.einsum("ij,ij->i", ms.measured - P, N) - R, d, atol=2e-5)
