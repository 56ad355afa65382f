# SPDX-License-Identifier: LGPL-2.1-or-later
"""Memory bounds (issue 25, item 7): sizes, the machine's memory, the estimates and the
refusal. Real peak figures are measured by bench/bench_memory.py, not here."""

import pytest

from surfcomp.cli.option_flags import flag
from surfcomp.core import budget
from surfcomp.core.simulation import simulate as sim
from surfcomp.errors import InputError

GB = 1024 ** 3


@pytest.mark.parametrize("text, value", [
    ("4G", 4 * GB), ("4 gb", 4 * GB), ("512M", 512 * 1024 ** 2), ("1.5GiB", int(1.5 * GB)),
    ("100000000", 100_000_000), (".25T", 256 * GB), ("65536k", 64 * 1024 ** 2),
])
def test_sizes(text, value):
    assert budget.parse_size(text) == value


@pytest.mark.parametrize("text, says", [
    ("", "expected a size"), ("4X", "expected a size"), ("-4G", "expected a size"),
    ("nan", "expected a size"), ("1e9", "expected a size"), ("63M", "at least 64 M"),
    ("0", "at least 64 M"), ("4G4", "expected a size"),
])
def test_sizes_refused(text, says):
    with pytest.raises(InputError, match=says):
        budget.parse_size(text)


def test_machine_memory_is_what_the_system_says(monkeypatch):
    pages = __import__("os").sysconf("SC_PHYS_PAGES")
    total = __import__("os").sysconf("SC_PAGE_SIZE") * pages
    monkeypatch.setattr(budget, "_cgroup_limit", lambda: None)
    assert budget.machine_memory() == total
    monkeypatch.setattr(budget, "_cgroup_limit", lambda: 2 * GB)
    assert budget.machine_memory() == min(total, 2 * GB)


def test_check_refuses_above_the_limit_and_names_it(monkeypatch):
    assert budget.check(GB, 2 * GB) == GB
    with pytest.raises(InputError) as err:
        budget.check(3 * GB, 2 * GB, "job X", "try less")
    assert str(err.value) == ("job X needs about 3.0 GB of memory, more than max_memory "
                              "(2.0 GB); try less")
    assert err.value.shown(flag) == ("job X needs about 3.0 GB of memory, more than "
                                     "--max-memory (2.0 GB); try less")
    monkeypatch.setattr(budget, "machine_memory", lambda: 512 * 1024 ** 2)
    with pytest.raises(InputError, match=r"more than the machine.s memory \(0.5 GB\)"):
        budget.check(GB)


def test_simulate_documented_maximum_fits_in_4_gb():
    """The largest grid with the default between = 2 (its evaluation grid is the largest
    allowed), four replicas of every method: estimated within 4 GB, and the former maximum
    4000 x 4000 far beyond."""
    n = sim.MAX_GRID
    e = sim.MAX_EVAL_GRID
    assert e == 2 * (n - 1) + 1
    assert budget.simulate_bytes(e * e, n * n, 4, 6) <= 4 * GB
    assert budget.simulate_bytes(7999 ** 2, 4000 ** 2, 4, 6) > 60 * GB
    # replicas count, so a billion of them is refused by any machine
    assert budget.simulate_bytes(45 ** 2, 45 ** 2, 10 ** 9, 6) > 10 ** 13


def test_estimates_grow_with_the_input():
    assert budget.job_bytes(3_000_000) > budget.job_bytes(1_000_000) > budget.job_bytes(10)
    assert budget.job_bytes(10 ** 6, build=True) > budget.job_bytes(10 ** 6)
    # G-code is compensated a block of lines at a time: at most 300 bytes a line beyond
    # the block
    assert budget.gcode_bytes(2_000_000) > budget.gcode_bytes(20_000) > budget.gcode_bytes(10)
    assert budget.gcode_bytes(2_000_000) - budget.gcode_bytes(20_000) <= 300 * 1_980_000
