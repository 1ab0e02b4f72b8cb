"""The values a sweep is given: value lists, ranges (grids) and distributions.

Each value is read as every front end reads an input's value (:mod:`restitution.inputs`): a number with
an optional unit (``"3mm"``, ``"114GPa"``, ``"1/4 in"``; a bare number is SI), a unit of another kind
refused naming the input. Dimensionless inputs (``sphere.nu``, tolerances, ``t_over_d``) and relative
spreads take plain numbers.

Values are the decimals they were given as, where a computation would leave them an ulp away
(:func:`decimal_like`): a unit's conversion (``4.5mm`` is 0.0045, not 0.0045000000000000005), and the
points of a ``linspace`` or ``arange`` whose ends and step are short decimals (``linspace:0.1:0.5:5``
gives 0.3, not numpy's 0.30000000000000004: each point is the double nearest its exact decimal
value); a ``geomspace`` or ``logspace`` point within two ulps of a decimal of 12 significant digits is
that decimal's double (``geomspace:2:32:5`` gives 8, not 7.999999999999999).
"""
from __future__ import annotations

import math
from decimal import Decimal

import numpy as np

from .._num import DECIMAL_BLOCK, POW10, decimal_like
from ..inputs import ROWS, QuantityError, quantities

__all__ = ["parse_values", "parse_distribution", "axis_size", "axis_form", "range_size", "range_values",
           "range_ends", "draw_standard", "from_standard", "MAX_AXIS_VALUES", "DISTRIBUTIONS"]


# --- value lists, ranges and distributions --------------------------------------------------
def _codes(name: str) -> dict | None:
    """word -> code of an integer-coded input, else None."""
    row = ROWS.get(name)
    return row.codes if row is not None and row.choices is not None else None


def _code(name: str, value):
    """An integer-coded parameter's code from a number or a word ('exact', 'e45', 'auto', ...)."""
    if isinstance(value, str):
        words = _codes(name)
        if value.strip() in words:
            return words[value.strip()]
        try:
            text = value.strip()
            value = int(text) if text.lstrip("+-").isdigit() and text.isascii() else float(text)
        except ValueError:
            raise ValueError(f"{name} = {value!r}: use one of {sorted(words)} or a code "
                             f"{sorted(words.values())}") from None
    try:
        integral = float(value) == int(value)
    except (OverflowError, ValueError):
        integral = False
    if not integral:
        raise ValueError(f"{name} = {value!r} is not an integer code")
    code = int(value)
    if code not in _codes(name).values():  # checked here: an FMU back end would wrap it to int32
        raise ValueError(f"{name} = {value!r} is out of range: use one of {sorted(_codes(name))} or a code "
                         f"{sorted(_codes(name).values())}")
    return code


def _numbers(name: str, items, text) -> np.ndarray:
    """SI values of ``items`` given together (codes for an integer-coded ``name``); ``text``: the whole value."""
    if _codes(name) is not None:
        return np.array([float(_code(name, v)) for v in items], dtype=float)
    return np.array(quantities(name, list(items), text), dtype=float)


def _plain(name: str, value, what: str) -> float:
    """A dimensionless number of a range or a distribution (a count, an exponent, a relative spread)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise QuantityError(f"{name} = {value!r}: {what}", name) from None


#: Largest grid axis [values]: an axis is materialised (8 bytes a value) where the cases are built.
MAX_AXIS_VALUES = 10**8


def _range_args(name: str, kind: str, args: list, text) -> list:
    """A range's numbers in SI: its ends (and arange's step) quantities, given all with units or none;
    a count and logspace's exponents plain numbers."""
    if kind == "logspace":
        return [_plain(name, a, "logspace takes exponents of ten and a count: plain numbers") for a in args]
    if kind == "arange":
        return quantities(name, args, text)
    return quantities(name, args[:2], text) + [_plain(name, a, f"the count of {kind} is a plain number")
                                               for a in args[2:]]


def _range_form(name: str, spec):
    """``(kind, args)`` of a linspace/geomspace/logspace/arange value range (args in SI), else None."""
    if isinstance(spec, str):
        kind, _, rest = spec.strip().partition(":")
        if rest and kind in ("linspace", "geomspace", "logspace", "arange"):
            return kind, _range_args(name, kind, rest.split(":"), spec)
        return None
    if isinstance(spec, dict):
        if len(spec) != 1:
            raise ValueError(f"{name}: a value range has exactly one key, got {sorted(spec)}")
        (kind, args), = spec.items()
        if kind not in ("linspace", "geomspace", "logspace", "arange"):
            raise ValueError(f"{name}: unknown value range {kind!r} (linspace, geomspace, logspace, arange)")
        return kind, _range_args(name, kind, list(args) if isinstance(args, (list, tuple)) else [args], spec)
    return None


def axis_size(name: str, spec) -> int:
    """Number of values :func:`parse_values` gives for ``spec``, without building them (a Python int)."""
    form = _range_form(name, spec)
    if form is None:
        if isinstance(spec, str):
            return len([x for x in spec.strip().split(",") if x.strip()])
        return len(spec) if isinstance(spec, (list, tuple, np.ndarray)) else 1
    return range_size(name, *form)


def range_size(name: str, kind: str, args: list) -> int:
    """Number of values of a range ``(kind, args)`` (args in SI), checked, without building it."""
    if not all(math.isfinite(a) for a in args):
        raise ValueError(f"{name}: {kind} needs finite numbers, got {args!r}")
    if kind == "arange":
        if len(args) not in (1, 2, 3):
            raise ValueError(f"{name}: arange needs [stop], [start, stop] or [start, stop, step]")
        start, stop, step = (0.0, args[0], 1.0) if len(args) == 1 else (*args, 1.0)[:3]
        if step == 0:
            raise ValueError(f"{name}: arange step = 0: the step must be non-zero")
        return max(0, math.ceil((stop - start) / step))
    if len(args) != 3 or int(args[2]) != args[2] or args[2] < 1:
        raise ValueError(f"{name}: {kind} needs [first, last, count] with an integer count >= 1")
    if kind == "geomspace" and (args[0] == 0 or args[1] == 0 or (args[0] < 0) != (args[1] < 0)):
        raise ValueError(f"{name}: geomspace needs first and last non-zero and of the same sign, got {args[:2]!r}")
    return int(args[2])


def _scaled(*numbers: float):
    """(the numbers as integers, k): each number's shortest decimal (its repr) times 10**k, k its most
    decimal places; None beyond k = 22 (10**k no longer exact as a double)."""
    decimals = [Decimal(repr(float(x))) for x in numbers]
    k = max(0, *(-d.as_tuple().exponent for d in decimals))
    return ([int(d.scaleb(k)) for d in decimals], k) if k <= 22 else None


def _decimal_points(start: int, step: int, n: int, k: int) -> np.ndarray | None:
    """(start + i step) / 10**k for i < n, each the double nearest that decimal (an exact integer over an
    exact power of ten, one correctly rounded division); None where an integer passes 2**53."""
    if max(abs(start), abs(start + (n - 1) * step)) >= 2**53:
        return None
    out = np.empty(n)
    for lo in range(0, n, DECIMAL_BLOCK):
        ints = np.arange(lo, min(n, lo + DECIMAL_BLOCK), dtype=np.int64)
        out[lo:lo + ints.size] = (ints * step + start).astype(np.float64) / POW10[k]
    return out


def _decimal_range(kind: str, args: list, n: int) -> np.ndarray | None:
    """A linspace's or arange's points as the decimals they are (:func:`_decimal_points`) when its ends and
    step are decimals (a linspace's step: (last - first) / (n - 1) with at most 22 places); else None."""
    if kind == "linspace":
        if n == 1:
            return np.array([float(args[0])])
        got = _scaled(args[0], args[1])
        if got is None:
            return None
        (first, last), k = got
        for more in range(23 - k):  # the fewest further places that make the step an integer
            span = (last - first) * 10**more
            if span % (n - 1) == 0:
                return _decimal_points(first * 10**more, span // (n - 1), n, k + more)
        return None
    start, _stop, step = (0.0, args[0], 1.0) if len(args) == 1 else (*args, 1.0)[:3]
    got = _scaled(start, step)
    return None if got is None else _decimal_points(got[0][0], got[0][1], n, got[1])


def range_values(name: str, kind: str, args: list) -> np.ndarray:
    """The values of a range ``(kind, args)``, at most :data:`MAX_AXIS_VALUES`: a linspace's and an
    arange's points as the decimals they are where its ends and step are decimals, else numpy's points
    (:func:`decimal_like`, a linspace's and a geomspace's ends exactly as given)."""
    size = range_size(name, kind, args)
    if size > MAX_AXIS_VALUES:
        raise ValueError(f"{name}: {kind} gives {size:,} values; at most {MAX_AXIS_VALUES:,} per axis")
    if kind in ("linspace", "arange") and size:
        values = _decimal_range(kind, args, size)
        if values is not None:
            return values
    if kind == "arange":
        return decimal_like(np.arange(*args))
    fn = {"linspace": np.linspace, "geomspace": np.geomspace, "logspace": np.logspace}[kind]
    values = decimal_like(fn(args[0], args[1], int(args[2])))
    if kind != "logspace" and values.size:
        values[0], values[-1] = args[0], args[1]  # numpy's, exactly
    return values


def range_ends(name: str, kind: str, args: list) -> list:
    """The first and last values of a range, without building it (those :func:`range_values` gives)."""
    n = range_size(name, kind, args)
    if n == 0:
        return []
    if kind == "arange":
        start, _stop, step = (0.0, args[0], 1.0) if len(args) == 1 else (*args, 1.0)[:3]
        got = _scaled(start, step)
        ends = None if got is None else _decimal_points(got[0][0] + (n - 1) * got[0][1], 0, 1, got[1])
        first, last = start, float(ends[0] if ends is not None else decimal_like(start + (n - 1) * step))
    elif kind == "logspace":
        first, last = (float(decimal_like(10.0 ** a)) for a in args[:2])
    else:
        first, last = args[0], args[1]
    return [first] if n == 1 else [first, last]


def parse_values(name: str, spec) -> np.ndarray:
    """Grid values in SI: a number, a list, ``{"linspace": [a, b, n]}``, ``{"geomspace": [a, b, n]}``,
    ``{"arange": [a, b, step]}``, or the CLI forms ``"a,b,c"``, ``"linspace:a:b:n"``, ``"geomspace:a:b:n"``;
    each value a number (SI) or text with a unit (``"3mm"``, ``"linspace:1mm:5mm:5"``)."""
    form = _range_form(name, spec)
    if form is not None:
        values = range_values(name, *form)
    elif isinstance(spec, str):
        values = _numbers(name, [v for v in spec.strip().split(",") if v.strip()], spec)
    elif isinstance(spec, (list, tuple, np.ndarray)):
        values = _numbers(name, spec, spec)
    else:
        values = _numbers(name, [spec], spec)
    if values.size == 0:
        raise ValueError(f"{name}: no values")
    return values


#: distribution -> number of parameters.
DISTRIBUTIONS = {"uniform": 2, "loguniform": 2, "normal": 2, "normal_rel": 1, "uniform_rel": 1, "choice": None}


def parse_distribution(name: str, spec) -> tuple[str, tuple]:
    """A random parameter's distribution: ``{"uniform": [lo, hi]}``, ``{"loguniform": [lo, hi]}``,
    ``{"normal": [mean, sd]}``, ``{"normal_rel": sd}`` (base value x (1 + sd N(0,1))),
    ``{"uniform_rel": h}`` (base value x U(1-h, 1+h)), ``{"choice": [values]}``, or the CLI
    form ``"uniform:lo:hi"``, ``"normal_rel:0.02"``, ``"choice:a,b,c"``. The base value of the
    relative forms is what the case has without the draw (material pair, grid, fixed or start value).
    The parameters of the absolute forms take units (``"uniform:1mm:5mm"``; bare numbers are SI), the
    relative spreads are plain numbers."""
    text = spec
    if isinstance(spec, str):
        kind, _, rest = spec.strip().partition(":")
        if kind == "choice":
            args = [x for x in rest.split(",") if x.strip()]
        else:
            args = [x for x in rest.split(":") if x.strip()]
        spec = {kind: args}
    if not isinstance(spec, dict) or len(spec) != 1:
        raise ValueError(f"{name}: a distribution is one of {sorted(DISTRIBUTIONS)} with its parameters, got {spec!r}")
    (kind, args), = spec.items()
    if kind not in DISTRIBUTIONS:
        raise ValueError(f"{name}: unknown distribution {kind!r} (one of {sorted(DISTRIBUTIONS)})")
    args = list(args) if isinstance(args, (list, tuple)) else [args]
    if kind == "choice":
        if not args:
            raise ValueError(f"{name}: choice needs at least one value")
        return kind, tuple(float(a) for a in _numbers(name, args, text))
    if len(args) != DISTRIBUTIONS[kind]:
        raise ValueError(f"{name}: {kind} takes {DISTRIBUTIONS[kind]} parameter(s), got {args!r}")
    if kind.endswith("_rel"):
        args = tuple(_plain(name, a, f"{kind} takes a relative spread, a plain number (0.03 is 3 %)") for a in args)
    else:
        args = tuple(quantities(name, args, text))
    if kind in ("uniform", "loguniform") and not args[0] < args[1]:
        raise ValueError(f"{name}: {kind} needs low < high, got {args!r}")
    if kind == "loguniform" and args[0] <= 0:
        raise ValueError(f"{name}: loguniform needs low > 0, got {args!r}")
    if kind != "uniform" and kind != "loguniform" and min(args[1:] if kind == "normal" else args) < 0:
        raise ValueError(f"{name}: {kind} needs a spread >= 0, got {args!r}")
    if _codes(name) is not None and kind != "choice":
        raise ValueError(f"{name} is integer-coded: only 'choice' can draw it")
    return kind, args


def draw_standard(rng: np.random.Generator, kind: str, n_choices: int, out: np.ndarray) -> None:
    """Fill ``out`` with the draws of ``kind`` before their parameters apply: uniform numbers in
    [0, 1) for the uniform kinds, standard normal ones for the normal kinds, indices for ``choice``
    (``out`` of integers, ``n_choices`` values). The numbers are the generator's, in its order, as
    ``rng.uniform``, ``rng.standard_normal`` and ``rng.integers`` draw them."""
    if kind in ("normal", "normal_rel"):
        rng.standard_normal(out=out)
    elif kind == "choice":
        out[...] = rng.integers(0, n_choices, out.size)
    else:
        rng.random(out=out)


def from_standard(kind: str, args: tuple, base: np.ndarray) -> np.ndarray:
    """The values of :func:`draw_standard`'s ``base`` draws (overwritten, where they are floats):
    ``low + (high - low) u`` as ``rng.uniform(low, high)`` computes it, the exponential of that for
    ``loguniform``, ``mean + sd z`` for the normal kinds, the listed values for ``choice``. One
    vectorized pass over a whole chunk, where per-block ``rng.uniform`` calls cost 2.5x more."""
    if kind == "choice":
        return np.asarray(args, dtype=float)[base]
    if kind == "normal":
        low, scale = args[0], args[1]
    elif kind == "normal_rel":
        low, scale = 1.0, args[0]
    elif kind == "uniform":
        low, scale = args[0], args[1] - args[0]
    elif kind == "uniform_rel":
        low, scale = 1.0 - args[0], (1.0 + args[0]) - (1.0 - args[0])
    else:  # loguniform
        low, scale = math.log(args[0]), math.log(args[1]) - math.log(args[0])
    np.multiply(base, scale, out=base)
    np.add(base, low, out=base)
    return np.exp(base, out=base) if kind == "loguniform" else base


def axis_form(name: str, spec) -> tuple:
    """``(kind, args)`` of a grid axis in SI: a range's kind and numbers (checked, not built), or
    ``("values", array)`` for a list and an integer-coded parameter (small: checked now)."""
    form = _range_form(name, spec)
    if form is not None and _codes(name) is None:
        range_size(name, *form)
        return form
    size = axis_size(name, spec)
    if size > 1000:
        raise ValueError(f"{name}: {size:,} listed values; give a range (linspace, geomspace, arange) for long axes")
    return "values", parse_values(name, spec)
