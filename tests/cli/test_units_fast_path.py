"""The common units read without pint (restitution.units._SI_FACTOR): the same SI float pint gives, for
every unit of the table, the docs' example values and random ones; any other unit or spelling read by
pint, with pint's messages; and ``restitution cor`` with units not loading pint at all.

Floats are compared for equality on purpose: pint converts by one IEEE-754 multiplication,
``number * factor``, and the fast path does the same multiplication by the same double, so the result is
the same float on every CPU (the issue asks for results unchanged, and a tolerance would hide a factor one
bit off, which is what would change them)."""
import random
import re
import subprocess
import sys
from pathlib import Path

import pytest

from restitution import units
from restitution.units import UnitError, convert_quantity, read_quantity, split_quantity

pint = pytest.importorskip("pint", reason="pint (the reference for the unit factors) is not installed")

ROOT = Path(__file__).resolve().parents[2]
FAST = [(kind, unit) for kind, table in units._SI_FACTOR.items() for unit in table]
#: "<number> <unit>" in quotes, as the docs write values.
_QUOTED_VALUE = re.compile(r'"([-+]?[0-9][0-9./eE+-]* ?[^"\s]{1,8})"')


@pytest.fixture(scope="module")
def ureg():
    """pint's registry, built here, apart from the code under test."""
    return pint.UnitRegistry()


def _pint_si(ureg, number: float, unit: str, kind: str) -> float:
    """What pint gives for ``number`` ``unit`` in the SI unit of ``kind`` (an exponent written as digits,
    "kg/m3", spelled as pint reads it)."""
    spelled = lambda text: re.sub(r"(?<=[A-Za-z\u00b5\u03bc])([0-9]+)\b", r"**\1", text)
    return float(ureg.Quantity(number, ureg.parse_units(spelled(unit)))
                 .to(ureg.parse_units(spelled(units.QUANTITIES[kind]))).magnitude)


@pytest.fixture
def without_pint(monkeypatch):
    """The unit reader with pint out of reach: a conversion that needs pint fails the test."""
    def refuse():
        raise AssertionError("pint's registry was asked for")

    monkeypatch.setattr(units, "_registry", refuse)


def _values(count: int, seed: int) -> list[float]:
    """Values as users write them (a few decimals, 0 to 1000) and across the range of floats (1e-12 to
    1e12, full mantissas), both signs."""
    rng = random.Random(seed)
    values = [round(rng.uniform(0, 1000), rng.randint(0, 4)) for _ in range(count)]
    values += [10 ** rng.uniform(-12, 12) for _ in range(count)]
    return values + [-v for v in values[::7]] + [0.0, -0.0, 1.0, 0.25, 1 / 3]


@pytest.mark.parametrize("kind, unit", FAST)
def test_each_unit_of_the_table_is_pints_factor_to_the_last_bit(ureg, kind, unit):
    src, dst = (ureg.parse_units(re.sub(r"(?<=[A-Za-z])([0-9]+)\b", r"**\1", u))
                for u in (unit, units.QUANTITIES[kind]))
    assert units._SI_FACTOR[kind][unit] == ureg._get_conversion_factor(src._units, dst._units)


@pytest.mark.parametrize("kind, unit", FAST)
def test_the_fast_path_gives_pints_float_for_random_values(ureg, without_pint, kind, unit):
    for number in _values(400, seed=FAST.index((kind, unit))):
        fast = convert_quantity("x", f"{number} {unit}", number, unit, kind)
        assert fast == _pint_si(ureg, number, unit, kind), (number, unit)
        assert type(fast) is float


def _docs_values() -> list[str]:
    """Every quoted "<number> <unit>" of the docs and the README whose unit is in the table."""
    table = {unit for _, unit in FAST}
    found = set()
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        for text in _QUOTED_VALUE.findall(page.read_text(encoding="utf-8")):
            parsed = split_quantity(text, fractions=True)
            if parsed is not None and parsed[1] in table:
                found.add(text)
    return sorted(found)


def test_the_docs_examples_read_as_pint_reads_them(ureg, without_pint):
    examples = _docs_values()
    assert len(examples) >= 20, examples  # the docs quote about 40 such values; fewer means the scan broke
    for text in examples:
        number, unit = split_quantity(text, fractions=True)
        kind = next(k for k, u in FAST if u == unit)
        assert read_quantity("--x", text, units.QUANTITIES[kind], kind) == _pint_si(ureg, number, unit, kind), text


@pytest.mark.parametrize("unit, kind", [
    ("millimeter", "length"), ("millimeters", "length"), ("inch", "length"), ("meter", "length"),
    ("m s^-1", "speed"), ("meter/second", "speed"), ("m/s**2", "acceleration"), ("kg/m^3", "density"),
    ("gigapascal", "pressure"), ("psi", "pressure"), ("mile/hour", "speed"), ("second", "time"),
    ("kg / m3", "density"), ("MM", "length"),
])
def test_other_spellings_are_read_by_pint(ureg, monkeypatch, unit, kind):
    asked = []
    real = units._registry
    monkeypatch.setattr(units, "_registry", lambda: asked.append(1) or real())
    try:
        expected = _pint_si(ureg, 6.35, unit, kind)
    except Exception:  # noqa: BLE001 - a spelling pint refuses ("MM"): the reader must refuse it too
        with pytest.raises(UnitError):
            convert_quantity("x", f"6.35 {unit}", 6.35, unit, kind)
    else:
        assert convert_quantity("x", f"6.35 {unit}", 6.35, unit, kind) == expected
    assert asked, f"{unit!r} did not go to pint"


@pytest.mark.parametrize("text, kind, message", [
    ("3 mm", "pressure", "'3 mm': mm is a unit of length, but d is a pressure (units: Pa, kPa, MPa, GPa)"),
    ("3 GPa", "length", "'3 GPa': GPa is a unit of pressure, but d is a length (units: m, cm, mm, um, in)"),
    ("3 m/s", "density", "'3 m/s': m/s is a unit of speed, but d is a density (units: kg/m3, g/cm3)"),
    ("3 s", "speed", "'3 s': s is a unit of time, but d is a speed (units: m/s, cm/s, mm/s, km/h)"),
    ("3 furlongs", "pressure", "'3 furlongs': furlongs is a unit of length, but d is a pressure "
                               "(units: Pa, kPa, MPa, GPa)"),
    ("3 mmm", "length", "'3 mmm': unknown unit 'mmm' for a length (units: m, cm, mm, um, in)"),
    ("3 kg", "length", "'3 kg': kg is a unit of [mass], but d is a length (units: m, cm, mm, um, in)"),
])
def test_a_unit_of_another_kind_or_unknown_keeps_pints_message(text, kind, message):
    """A unit of the table given for another kind is not converted by the table: pint reads it and
    the refusal is worded as before."""
    number, unit = split_quantity(text)
    with pytest.raises(UnitError) as refused:
        convert_quantity("d", text, number, unit, kind)
    assert str(refused.value) == message


@pytest.mark.parametrize("text", ["1e308 km", "1e300 GPa"])
def test_an_overflow_is_refused_as_not_finite(without_pint, text):
    number, unit = split_quantity(text)
    kind = next(k for k, u in FAST if u == unit)
    with pytest.raises(UnitError, match="is not finite"):
        convert_quantity("d", text, number, unit, kind)


def test_cor_with_units_does_not_load_pint():
    """The issue's command, a fresh process: it reads its values without importing pint (``-X importtime``
    lists on stderr every module the command imports)."""
    args = ["--sphere", "chrome_steel", "--d", "6.35 mm", "--plate", "al_6061", "--t", "1/4 in", "--v", "2.3 m/s"]
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "restitution", "cor", *args],
                          capture_output=True, text=True, timeout=120)
    imported = [line.rsplit("|", 1)[-1].strip() for line in done.stderr.splitlines() if line.startswith("import time:")]
    assert done.returncode == 0 and "apparent COR" in done.stdout, done.stderr[-2000:]
    assert "restitution.units" in imported and not [m for m in imported if m.split(".")[0] == "pint"]
