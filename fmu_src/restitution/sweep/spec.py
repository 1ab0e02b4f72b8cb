"""What a sweep covers: material pairs, grid axes, random draws and fixed values, by FMU name.

A sweep is the full-factorial product of its *grid* axes (material pairs first, then the
axes in the order given), and at every grid point ``samples`` cases whose *random*
parameters are drawn independently. Every case carries all 17 FMU inputs and parameters
(unset ones at the FMU's start values), so each back end gets the same explicit table.

Case ``i`` is built from the spec and ``i`` alone: any block of cases can be generated where
it is evaluated (on a Dask worker), and the random draws do not depend on how the sweep is
cut into chunks (they come in fixed blocks of :data:`RANDOM_BLOCK` cases, each seeded with
``(seed, block index)``).

Names are the FMU's (``sphere.E``, ``plate.t``, ``v_approach``, ...); the package's
keyword names (``sphere_E``, ``plate_t``, ``v``) are accepted too. ``t_over_d`` is a derived
axis: ``plate.t = t_over_d * sphere.d``. Values take units (``"3mm"``, ``"114 GPa"``; a bare number
is SI, :mod:`restitution.inputs`); :meth:`SweepSpec.check_domain` checks the explicit ones
against the inputs' declared ranges.
"""
from __future__ import annotations

import contextlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fmu.models.sphere_plate_impact.variables import fmu_values
from ..materials import MATERIALS
from ..inputs import ROWS, QuantityError, outside
from .columns import (CODES, INPUT_NAMES, INPUTS, INTEGER_INPUTS, OUTPUT_NAMES, OUTPUTS,  # noqa: F401
                      SETTABLE, START, T_OVER_D, is_one_value_view, pair_label, resolve_pair)  # (named here too)
from .values import (MAX_AXIS_VALUES, axis_form, axis_size, draw_standard, from_standard,  # noqa: F401 (axis_size)
                     parse_distribution, parse_values, range_ends, range_size, range_values)

__all__ = ["SweepSpec", "INPUTS", "OUTPUTS", "CODES", "RANDOM_BLOCK", "canonical_name", "load_spec",
           "parse_values", "parse_distribution", "resolve_pair", "SizeError", "QuantityError"]


class SizeError(ValueError):
    """A sweep refused before any work by the size guard: an axis too long to build, or a table too
    big for the memory budget and for the disk (the message gives the numbers)."""


#: Material-property inputs a material pair sets.
PAIR_INPUTS = tuple(fmu_values(**MATERIALS["s2_tool_steel"].params("sphere"), **MATERIALS["al_6061"].params("plate")))
#: Largest ``samples`` and ``seed`` a spec accepts.
MAX_SAMPLES = 10**12
MAX_SEED = 2**63 - 1
#: Random draws come in blocks of this many cases, each from its own seeded generator.
RANDOM_BLOCK = 4096

_ALIASES = {row[1]: row[0] for row in INPUTS}
_ALIASES.update({"v": "v_approach", "speed": "v_approach", "ode_rtol": "zener.ode_tolerance",
                 "t/d": T_OVER_D, "t_d": T_OVER_D})


def canonical_name(name: str) -> str:
    """The FMU name of an input/parameter given by FMU name, impact() keyword or alias."""
    name = name.strip()
    if name in START or name == T_OVER_D:
        return name
    if name in _ALIASES:
        return _ALIASES[name]
    raise ValueError(f"unknown sweep parameter {name!r}: use an FMU input/parameter name "
                     f"({', '.join(INPUT_NAMES)}) or {T_OVER_D!r}")


def _pair_values(pair: str) -> dict:
    sphere, plate = resolve_pair(pair)
    return fmu_values(**sphere.params("sphere"), **plate.params("plate"))


# --- the spec --------------------------------------------------------------------------
@contextlib.contextmanager
def _section(section: str):
    """A :class:`QuantityError` raised inside names ``section`` (where its value was given)."""
    try:
        yield
    except QuantityError as exc:
        exc.section = exc.section or section
        raise


@dataclass
class SweepSpec:
    """A grid and/or random sample over FMU inputs/parameters (see the module docstring).

    >>> spec = SweepSpec(pairs=["s2_tool_steel/al_6061"],
    ...                  grid={"v_approach": {"geomspace": [0.1, 10, 40]}, "t_over_d": {"geomspace": [0.1, 10, 30]}})
    >>> spec.n_cases
    1200
    """

    pairs: list = field(default_factory=list)
    grid: dict = field(default_factory=dict)
    random: dict = field(default_factory=dict)
    fixed: dict = field(default_factory=dict)
    samples: int = 1
    seed: int = 0

    def __post_init__(self):
        self.pairs = [str(p).strip() for p in self.pairs]
        for p in self.pairs:
            resolve_pair(p)
        if len(set(self.pairs)) != len(self.pairs):
            raise ValueError(f"pairs: duplicate entries in {self.pairs}")
        self.grid = {canonical_name(k): v for k, v in self.grid.items()}
        self.random = {canonical_name(k): v for k, v in self.random.items()}
        self.fixed = {canonical_name(k): v for k, v in self.fixed.items()}
        with _section("grid"):  # units are read here: a worker builds its axes from SI numbers
            self._forms = {k: axis_form(k, v) for k, v in self.grid.items()}
        self._axis_sizes = {k: args.size if kind == "values" else range_size(k, kind, args)
                            for k, (kind, args) in self._forms.items()}
        self._axes_built = None  # the axes' values, built when cases are (see _axes)
        with _section("random"):
            self._dists = {k: parse_distribution(k, v) for k, v in self.random.items()}
        with _section("fixed"):
            self._fixed = {k: parse_values(k, v) for k, v in self.fixed.items()}
        for k, v in self._fixed.items():
            if v.size != 1:
                raise ValueError(f"fixed {k}: one value, got {v.size} (use the grid for several)")
        for key in ("samples", "seed"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) and not (
                    isinstance(value, float) and value.is_integer()):
                raise ValueError(f"{key} = {value!r}: expected an integer")
        self.samples = int(self.samples)
        self.seed = int(self.seed)
        if not 1 <= self.samples <= MAX_SAMPLES:
            raise ValueError(f"samples = {self.samples}: must be in 1 ... {MAX_SAMPLES}")
        if not 0 <= self.seed <= MAX_SEED:
            raise ValueError(f"seed = {self.seed}: must be in 0 ... {MAX_SEED} (2**63 - 1)")
        if self.samples > 1 and not self._dists:
            raise ValueError("samples > 1 needs at least one random parameter")
        # Each input gets its value from one place; relative draws scale whatever that is.
        sources = {}
        for where, names in (("fixed", self._fixed), ("grid", self._axis_sizes),
                             ("random", {k for k, (kind, _) in self._dists.items() if not kind.endswith("_rel")})):
            for k in names:
                if k in sources:
                    raise ValueError(f"{k} is set twice ({sources[k]} and {where})")
                sources[k] = where
        if self.pairs:
            for k in PAIR_INPUTS:
                if k in sources:
                    raise ValueError(f"{k} is set by the material pairs and by {sources[k]}: "
                                     f"scatter it with a relative draw (normal_rel, uniform_rel) instead")
        if T_OVER_D in sources and "plate.t" in sources:
            raise ValueError(f"plate.t and {T_OVER_D} both set: give one of them")
        for k, (kind, _) in self._dists.items():
            if kind.endswith("_rel") and k == T_OVER_D and T_OVER_D not in sources:
                raise ValueError(f"{k}: a relative draw needs a base value from the grid or fixed")

    def check_domain(self) -> None:
        """:class:`QuantityError` (a ValueError, one line) for the first explicit value outside its
        input's declared range: a fixed value, a value of a grid list, the first or last value of a grid
        range, and ``plate.t`` as ``t_over_d`` times ``sphere.d`` gives it at their ends. Random draws
        are not checked: a case they take outside is a row with ``ok = False``. The command line calls
        it before any work; :func:`run_sweep` does not (such cases are rows with ``ok = False``)."""
        explicit = {k: ("fixed", [float(v[0])]) for k, v in self._fixed.items()}
        explicit.update({k: ("grid", list(args) if kind == "values" else range_ends(k, kind, args))
                         for k, (kind, args) in self._forms.items() if k not in CODES})
        for k, (section, values) in explicit.items():
            for value in values:
                problem = outside(k, value)
                if problem:
                    raise QuantityError(problem, k, section)
        drawn = self._dists.get("sphere.d", ("", ()))[0]
        if T_OVER_D in explicit and (not drawn or drawn.endswith("_rel")):
            section, ratios = explicit[T_OVER_D]
            for ratio in ratios:
                for d in explicit.get("sphere.d", ("", [float(START["sphere.d"])]))[1]:
                    if outside("plate.t", ratio * d):
                        raise QuantityError(
                            f"{T_OVER_D} = {ratio:.15g} with sphere.d = {d:.15g} m gives plate.t = {ratio * d:.15g} m, "
                            f"outside {ROWS['plate.t'].allowed_text()} m", T_OVER_D, section)

    # --- structure ---
    def check_axes(self) -> None:
        """:class:`SizeError` when an axis has more values than :data:`MAX_AXIS_VALUES` (each worker
        builds the axes it draws its cases from), from the sizes alone."""
        for k, size in self._axis_sizes.items():
            if size > MAX_AXIS_VALUES:
                raise SizeError(f"{k}: the axis has {size:,} values; at most {MAX_AXIS_VALUES:,} per axis "
                                f"(each worker builds it): use a coarser axis or a random draw")

    @property
    def distributions(self) -> dict:
        """The random inputs as parsed: name -> (kind, parameters in SI), e.g. ("uniform_rel", (0.15,))."""
        return self._dists

    @property
    def _axes(self) -> dict:
        if self._axes_built is None:
            self._axes_built = {k: args if kind == "values" else range_values(k, kind, args)
                                for k, (kind, args) in self._forms.items()}
        return self._axes_built

    @property
    def axes(self) -> dict:
        """Grid axes in iteration order (material pairs first, as indices into :attr:`pairs`)."""
        axes = {}
        if self.pairs:
            axes["pair"] = np.arange(len(self.pairs), dtype=float)
        axes.update(self._axes)
        return axes

    @property
    def shape(self) -> tuple:
        """Axis sizes (Python ints; the axes are not built)."""
        return ((len(self.pairs),) if self.pairs else ()) + tuple(self._axis_sizes.values())

    @property
    def n_grid(self) -> int:
        return math.prod(self.shape)  # Python ints: no wrap however large

    @property
    def n_cases(self) -> int:
        return self.n_grid * self.samples

    def as_dict(self) -> dict:
        """JSON-able form that :meth:`from_dict` reads back."""
        def plain(v):
            if isinstance(v, np.ndarray):
                return v.tolist()
            if isinstance(v, dict):
                return {k: plain(x) for k, x in v.items()}
            if isinstance(v, (list, tuple)):
                return [plain(x) for x in v]
            return v
        return {"pairs": list(self.pairs), "grid": plain(self.grid), "random": plain(self.random),
                "fixed": plain(self.fixed), "samples": self.samples, "seed": self.seed}

    @classmethod
    def from_dict(cls, data: dict) -> "SweepSpec":
        if not isinstance(data, dict):
            raise ValueError(f"a sweep spec is a table (pairs, grid, random, fixed, samples, seed), "
                             f"got {type(data).__name__}")
        data = dict(data)
        data.pop("run", None)  # run options (back end, scheduler, output) live beside the spec
        unknown = set(data) - {"pairs", "grid", "random", "fixed", "samples", "seed"}
        if unknown:
            raise ValueError(f"unknown sweep spec key(s) {sorted(unknown)}: "
                             f"use pairs, grid, random, fixed, samples, seed (and a [run] table)")
        check_types(data)
        return cls(**data)

    # --- cases ---
    def cases(self, start: int = 0, stop: int | None = None) -> dict:
        """Columns of cases ``start <= i < stop``: ``case``, ``pair`` (index into :attr:`pairs`,
        -1 without pairs), every FMU input/parameter by name, and ``t_over_d``.

        A column that holds one value for every case of the range (a start value, a fixed parameter,
        a material constant and ``pair`` where the range has one pair) is a read-only view of that value
        (``numpy.broadcast_to``): no memory is written for it, and the table is filled from the value."""
        n = self.n_cases
        stop = n if stop is None else min(int(stop), n)
        start = int(start)
        if not 0 <= start <= stop:
            raise ValueError(f"case range [{start}, {stop}) outside [0, {n})")
        index = np.arange(start, stop, dtype=np.int64)
        cols = {name: float(START[name]) for name in INPUT_NAMES}  # a float: one value for the whole range
        for k, v in self._fixed.items():
            if k != T_OVER_D:
                cols[k] = float(v[0])
        # Grid coordinates, C order (last axis fastest).
        axes = self.axes
        coords = {}
        rem = (index // self.samples if self.samples > 1 else index.copy()) if axes else None
        for name, values in reversed(list(axes.items())):
            coords[name] = values[rem % values.size]
            rem //= values.size
        pair = np.broadcast_to(np.int64(-1), index.shape)
        if self.pairs:
            pair = coords.pop("pair").astype(np.int64)
            one_pair = pair.size > 0 and pair.min() == pair.max()  # the usual range: inside one pair's block
            values = [_pair_values(p) for p in self.pairs]
            for k in values[0]:
                by_pair = np.array([v[k] for v in values], dtype=float)
                cols[k] = float(by_pair[pair[0]]) if one_pair else by_pair[pair]
            if one_pair:  # like the pair's constants: a view of its one value
                pair = np.broadcast_to(pair[:1], index.shape)
        t_over_d = None
        for k, v in coords.items():
            if k == T_OVER_D:
                t_over_d = v
            else:
                cols[k] = v
        if T_OVER_D in self._fixed:
            t_over_d = float(self._fixed[T_OVER_D][0])
        cols = {k: np.broadcast_to(np.float64(v), index.shape) if isinstance(v, float) else v
                for k, v in cols.items()}
        # Random draws, in blocks independent of the chunking.
        if self._dists:
            draws = self._random_draws(start, stop)
            for k, (kind, _args) in self._dists.items():
                if k == T_OVER_D:
                    t_over_d = draws[k] * t_over_d if kind.endswith("_rel") else draws[k]
                elif kind.endswith("_rel"):
                    cols[k] = cols[k] * draws[k]
                else:
                    cols[k] = draws[k]
        if t_over_d is not None:
            cols["plate.t"] = t_over_d * cols["sphere.d"]
        with np.errstate(divide="ignore", invalid="ignore"):
            cols[T_OVER_D] = cols["plate.t"] / cols["sphere.d"]
        out = {"case": index, "pair": pair}
        out.update(cols)
        return out

    def _random_draws(self, start: int, stop: int) -> dict:
        """Each random input's draws for cases start ... stop - 1: block b of RANDOM_BLOCK cases comes
        from its own generator seeded with (seed, b), whatever the chunking; the blocks' standard draws
        are gathered first and their parameters applied to the whole range at once."""
        first, last = start // RANDOM_BLOCK, (max(stop, start + 1) - 1) // RANDOM_BLOCK
        base = {k: np.empty(stop - start, dtype=np.intp if kind == "choice" else float)
                for k, (kind, _args) in self._dists.items()}
        block = {k: np.empty(RANDOM_BLOCK, dtype=v.dtype) for k, v in base.items()}
        for b in range(first, last + 1):
            rng = np.random.default_rng([self.seed, b])
            lo = max(start - b * RANDOM_BLOCK, 0)
            hi = min(stop - b * RANDOM_BLOCK, RANDOM_BLOCK)
            at = b * RANDOM_BLOCK + lo - start
            whole = hi - lo == RANDOM_BLOCK  # a whole block is drawn into place, a part through a buffer
            for k, (kind, args) in self._dists.items():
                out = base[k][at:at + RANDOM_BLOCK] if whole else block[k]
                draw_standard(rng, kind, len(args), out)
                if not whole:
                    base[k][at:at + hi - lo] = out[lo:hi]
        return {k: from_standard(kind, args, base[k]) for k, (kind, args) in self._dists.items()}

    def describe(self) -> str:
        bits = []
        if self.pairs:
            bits.append(f"{len(self.pairs)} material pair(s)")
        bits += [f"{k} x{size:,}" for k, size in self._axis_sizes.items()]
        if self._dists:
            bits.append(f"{self.samples:,} random sample(s) of {', '.join(self._dists)} per grid point")
        return f"{self.n_cases:,} cases: " + (", ".join(bits) if bits else "one case at the start values")


def check_types(data: dict) -> None:
    """ValueError (one line naming the key) unless ``pairs`` is a list of strings and ``grid``,
    ``random``, ``fixed`` are tables keyed by parameter names."""
    pairs = data.get("pairs", [])
    if not isinstance(pairs, (list, tuple)) or not all(isinstance(p, str) for p in pairs):
        raise ValueError(f"pairs = {pairs!r}: expected a list of 'sphere/plate' strings, "
                         f"e.g. pairs = [\"s2_tool_steel/al_6061\"]")
    for key in ("grid", "random", "fixed"):
        table = data.get(key, {})
        if not isinstance(table, dict):
            raise ValueError(f"{key} = {table!r}: expected a table of parameter = value(s), e.g. [{key}] v_approach = ...")
        for name, value in table.items():
            if not isinstance(name, str):
                raise ValueError(f"{key}: {name!r} is not a parameter name")
            if isinstance(value, dict) and key != "fixed" and len(value) == 1:
                continue  # a value range or a distribution: checked with its kind
            if not isinstance(value, (str, int, float, list, tuple, dict)) or isinstance(value, bool):
                raise ValueError(f"{key}.{name} = {value!r}: expected a number, a word, a list or a range")


def load_spec(path) -> dict:
    """The dict in a TOML or JSON spec file (``.toml`` / ``.json``)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"spec file {path}: {exc.strerror or exc}") from None
    except UnicodeDecodeError:
        raise ValueError(f"spec file {path}: not UTF-8 text") from None
    if path.suffix.lower() == ".json":
        try:
            return json.loads(text)
        except ValueError as exc:
            raise ValueError(f"spec file {path}: not valid JSON: {exc}") from None
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        try:
            import tomli as tomllib
        except ModuleNotFoundError:
            raise SystemExit(f"{path}: reading TOML needs Python >= 3.11 or `pip install tomli`; "
                             f"or write the spec as JSON") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"spec file {path}: not valid TOML: {exc}") from None
