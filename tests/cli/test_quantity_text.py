"""Reading "<number> <unit>" text (restitution.units.split_quantity): what is a number, where the
unit starts and ends, and text of any length read in time proportional to its length."""
import subprocess
import sys

import pytest

from restitution.units import split_quantity


@pytest.mark.parametrize("text, expected", [
    ("3.18 mm", (3.18, "mm")), (" 2  m/s ", (2.0, "m/s")), ("1e5", (1e5, None)), (".5 in", (0.5, "in")),
    ("5. mm", (5.0, "mm")), ("-2.5e-3 m", (-2.5e-3, "m")), ("7 kg / m3", (7.0, "kg / m3")),
])
def test_a_number_and_its_unit(text, expected):
    assert split_quantity(text) == expected


@pytest.mark.parametrize("text", ["mm", "", "   ", "\u0663.\u0661\u0668 mm", "e5 m", ". m"])
def test_text_that_does_not_start_with_a_number_in_ascii_digits_is_none(text):
    assert split_quantity(text) is None


def test_a_long_text_is_read_in_linear_time():
    """A 100,000-character value with a long run of blanks inside its unit: the unit is everything from its
    first to its last non-blank character. The old pattern (a lazy unit before trailing blanks) took time
    growing with the square of the length: about 2.5 minutes for this text; linear, it takes milliseconds.
    Run in a child process with a 60 s limit, so that a quadratic pattern fails instead of stalling."""
    code = ("from restitution.units import split_quantity\n"
            "text = '1 a' + ' ' * 100000 + 'b '\n"
            "number, unit = split_quantity(text)\n"
            "assert number == 1.0 and unit == 'a' + ' ' * 100000 + 'b', (number, len(unit))\n"
            "assert split_quantity('1' * 100000 + ' ' * 100000 + 'x')[1] == 'x'\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
