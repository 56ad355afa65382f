# SPDX-License-Identifier: LGPL-2.1-or-later
"""Table rows with another number of fields than the header: the line, the counts, the
separator, and what a row ending in a separator or written with decimal commas needs."""

import pytest

from tests.pure.test_io_measurements import nnd_text, parse_error


@pytest.mark.parametrize("row, found, extra", [("1,1,1,0,0,1", 6, ""),
                                               ("1,1,1,0,0,1,0.1,9", 8, ""),
                                               ("1,1,1,0,0,1,0.1,", 8, "ends with a separator")])
def test_ragged_rows(row, found, extra):
    e = parse_error("# c\n" + nnd_text() + row + "\n1,2\n")
    assert e.line == 7
    assert "has %d fields but the header on line 2 has 7 (expected 7 fields separated by ','" \
        % found in e.message
    assert extra in e.message


def test_decimal_commas_between_commas_are_named():
    """A comma-separated file written with decimal commas (a European locale) splits every
    number in two: the message says what the fields need."""
    e = parse_error(nnd_text() + "1,5,1,25,3,0,0,0,0,1,0,012\n")
    assert e.line == 6 and "has 12 fields but the header on line 1 has 7" in e.message
    assert "decimal commas? between comma-separated fields numbers need a decimal point" \
        in e.message
    assert "decimal commas" not in parse_error(nnd_text() + "1,1,1,0,0,1,0.1,9\n").message


def test_ragged_rows_with_blanks():
    e = parse_error(nnd_text(" ") + "1 1 1 0 0 1\n")
    assert e.line == 6 and "has 6 fields but the header on line 1 has 7" in e.message
    assert "separated by blanks" in e.message
