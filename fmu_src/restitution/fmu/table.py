"""The FMUs' interface as data: one row per variable, one table per model (``models/<model>/variables.py``).

Pure data and lookups (no pythonfmu, no fmpy): the pythonfmu slaves register their variables from
it, the build writes the modelDescription from it, :mod:`restitution.fmu.describe.c_header` generates the C
headers from it, and the host tools (sweeps, scenes, co-simulation helpers, the ctypes binding,
benchmarks) read names, package keywords and codes from it. Adding a variable is one row here plus
its physics. Shipped inside the pythonfmu FMUs with the physics (the slaves read it at run time).
"""
from __future__ import annotations

import hashlib
import json
import math
import uuid
from dataclasses import asdict, dataclass, replace

__all__ = ["Variable", "Table", "parameter", "input_", "output", "local", "calculated_parameter"]

CAUSALITIES = ("parameter", "input", "output", "local", "calculatedParameter")
TYPES = ("Real", "Integer", "Boolean")
#: SI base-unit exponents of every unit the tables use (unit string -> {base unit: exponent}; "1":
#: dimensionless), which both modelDescriptions' <UnitDefinitions> declare. A new unit in a table needs
#: its row here (the build fails with a KeyError otherwise).
UNITS = {
    "1": {},
    "m": {"m": 1},
    "s": {"s": 1},
    "kg": {"kg": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s2": {"m": 1, "s": -2},
    "Pa": {"kg": 1, "m": -1, "s": -2},
    "kg/m3": {"kg": 1, "m": -3},
}


@dataclass(frozen=True)
class Variable:
    """One scalar variable of an FMU (units and ranges in SI, as in the modelDescription)."""

    name: str  #: the FMU name ("sphere.E")
    key: str  #: the package keyword (inputs, parameters) or result field / model quantity (outputs, locals)
    type: str  #: "Real", "Integer" or "Boolean"
    causality: str  #: "parameter", "input", "output" or "local"
    variability: str  #: "fixed", "tunable", "discrete" or "continuous"
    unit: str | None
    description: str
    start: float | int | bool | None = None
    #: allowed values of an input or parameter: (low, high, low_open, high_open); a finite bound is
    #: closed (the modelDescription declares it as min or max, which FMI reads as inclusive: the declared
    #: range is the accepted range), an infinite bound open (non-finite values are refused); None for
    #: outputs and locals
    interval: tuple | None = None
    #: the allowed range as an error message shows it (None: from the interval)
    range_text: str | None = None
    #: the words of an Integer-coded choice, in code order (code of choices[i] = first_code + i)
    choices: tuple[str, ...] | None = None
    first_code: int = 1
    #: an output that depends directly on the inputs at the same communication point
    feedthrough: bool = False
    #: part of the FMU state: every input and parameter, and the outputs and locals the model evolves
    #: (the others are recomputed from the inputs)
    state: bool = False
    vr: int = -1  #: value reference: the row's position in its table
    #: an Integer choice that the modelDescription declares as an Enumeration of this type (its items
    #: the choices, with ``item_descriptions``); None: a plain Integer whose description lists the codes
    enumeration: str | None = None
    item_descriptions: tuple[str, ...] | None = None
    #: the FMU name of the continuous state this variable is the time derivative of (model exchange:
    #: the host integrates that state with this as its derivative); None: not a derivative
    derivative: str | None = None
    #: a model-exchange event indicator: the host locates where it crosses zero (a state event)
    event_indicator: bool = False
    #: the FMU names of the inputs and parameters this initial unknown depends on (the modelDescription's
    #: InitialUnknowns ``dependencies``); None: it may depend on every known (no attribute)
    initial_dependencies: tuple[str, ...] | None = None
    #: the narrower interval the native (C) FMUs accept, where they do not offer all of ``interval``
    #: (their modelDescriptions declare it); None: the same as ``interval``
    native_interval: tuple | None = None

    @property
    def initial(self) -> str | None:
        """The ``initial`` attribute the modelDescription declares (outputs and locals are calculated)."""
        return "calculated" if self.causality in ("output", "local", "calculatedParameter") else None

    @property
    def is_enumeration(self) -> bool:
        """An Integer whose values are named codes: FMI 3.0 declares it an Enumeration (FMI 2.0 an
        Integer, or an Enumeration where ``enumeration`` names its type)."""
        return self.choices is not None or self.enumeration is not None

    @property
    def codes(self) -> dict[str, int] | None:
        """word -> code of an Integer-coded choice ({"exact": 1, ...}), else None."""
        if self.choices is None:
            return None
        return {word: self.first_code + i for i, word in enumerate(self.choices)}

    def word(self, code: int) -> str:
        """The choice a code stands for (ValueError for another code)."""
        if self.choices is None or not self.first_code <= int(code) < self.first_code + len(self.choices):
            raise ValueError(f"{self.name} = {code!r} is not one of its codes")
        return self.choices[int(code) - self.first_code]

    def allowed_text(self) -> str | None:
        """What a refusal message gives as the allowed range ("0 <= value < 0.5", "1 = e45 or 2 = e44")."""
        if self.range_text is not None:
            return self.range_text
        if self.choices is not None:
            items = [f"{code} = {word}" for word, code in self.codes.items()]
            return ", ".join(items[:-1]) + " or " + items[-1] if len(items) > 1 else items[0]
        if self.interval is None:
            return None
        low, high, low_open, high_open = self.interval
        if high == math.inf:
            return f"finite and {'>' if low_open else '>='} {low:g}"
        return f"{low:g} {'<' if low_open else '<='} value {'<' if high_open else '<='} {high:g}"

    def accepts(self, value) -> bool:
        """Whether ``value`` lies in the allowed interval (NaN and, an infinite bound being open, +-inf never)."""
        low, high, low_open, high_open = self.interval
        if self.type == "Integer":
            value = int(value)  # ValueError for NaN, OverflowError for inf: the caller refuses the value
        return bool((low < value if low_open else low <= value) and (value < high if high_open else value <= high))

    def xml_limits(self, native: bool = False) -> tuple[str | None, str | None]:
        """The min and max attributes of the modelDescription (None where the bound is infinite), of the
        native FMUs' modelDescriptions where ``native``."""
        low, high = (self.native_interval if native and self.native_interval is not None else self.interval)[:2]
        return (None if low == -math.inf else f"{low:g}"), (None if high == math.inf else f"{high:g}")


def _settable(name, key, vtype, causality, variability, unit, start, description, interval=None, *,
              choices=None, first_code=1, range_text=None, enumeration=None, item_descriptions=None,
              native_interval=None):
    if choices is not None:
        interval = (first_code, first_code + len(choices) - 1, False, False)
    if interval is None:
        raise ValueError(f"{name}: an input or parameter needs its allowed interval")
    return Variable(name, key, vtype, causality, variability, unit, description, start, tuple(interval), range_text,
                    tuple(choices) if choices is not None else None, first_code, state=True,
                    enumeration=enumeration, item_descriptions=tuple(item_descriptions) if item_descriptions else None,
                    native_interval=tuple(native_interval) if native_interval is not None else None)


def parameter(name, key, unit, start, description, interval=None, *, vtype="Real", variability="tunable", **kw):
    """A parameter (tunable unless said otherwise); ``interval`` may be left out only for a choice."""
    return _settable(name, key, vtype, "parameter", variability, unit, start, description, interval, **kw)


def input_(name, key, unit, start, description, interval, **kw):
    """A continuous Real input allowed in ``interval``."""
    return _settable(name, key, "Real", "input", "continuous", unit, start, description, interval, **kw)


def output(name, key, unit, description, *, vtype="Real", feedthrough=False, state=False, initial_dependencies=None):
    """An output (Reals continuous, Integers and Booleans discrete)."""
    variability = "continuous" if vtype == "Real" else "discrete"
    return Variable(name, key, vtype, "output", variability, unit, description, feedthrough=feedthrough, state=state,
                    initial_dependencies=_names(initial_dependencies))


def calculated_parameter(name, key, unit, description):
    """A Real calculated parameter: computed from the parameters (tunable, as they are), not settable."""
    return Variable(name, key, "Real", "calculatedParameter", "tunable", unit, description)


def local(name, key, unit, description, *, state=True, derivative=None, event_indicator=False,
          initial_dependencies=None):
    """A continuous Real local variable (one the model evolves: part of the state, unless it is
    recomputed from the others, as a ``derivative`` of a continuous state or an ``event_indicator``)."""
    return Variable(name, key, "Real", "local", "continuous", unit, description, state=state, derivative=derivative,
                    event_indicator=event_indicator, initial_dependencies=_names(initial_dependencies))


def _names(names):
    return None if names is None else tuple(names)


class Table:
    """The variables of one model, value reference = position; looked up by FMU name."""

    def __init__(self, model: str, description: str, rows, constants: dict | None = None):
        self.model = model
        self.description = description
        #: name -> tuple of floats the model's C needs beside the rows (the generated header holds them
        #: as ``RST_<MODEL>_<NAME>[]``), e.g. the material presets by code
        self.constants = dict(constants or {})
        self.rows = tuple(replace(row, vr=i) for i, row in enumerate(rows))
        self._by_name = {row.name: row for row in self.rows}
        if len(self._by_name) != len(self.rows):
            raise ValueError(f"{model}: two variables share a name")
        for row in self.rows:
            if row.type not in TYPES or row.causality not in CAUSALITIES:
                raise ValueError(f"{model}.{row.name}: unknown type {row.type!r} or causality {row.causality!r}")
            if row.interval is not None and row.type == "Real":
                low, high, low_open, high_open = row.interval
                if (low_open and math.isfinite(low)) or (high_open and math.isfinite(high)):
                    raise ValueError(f"{model}.{row.name}: a finite bound must be closed (FMI's min and max are "
                                     "inclusive; declare the smallest or largest value accepted)")
                if any(text is not None and float(text) != bound for text, bound in zip(row.xml_limits(), (low, high))):
                    raise ValueError(f"{model}.{row.name}: a bound does not survive its modelDescription text")
            for known in row.initial_dependencies or ():
                if known not in self._by_name or self._by_name[known].causality not in ("parameter", "input"):
                    raise ValueError(f"{model}.{row.name}: initial dependency {known!r} is not an input or parameter")
            if row.derivative is not None and (row.derivative not in self._by_name
                                               or self._by_name[row.derivative].type != "Real"):
                raise ValueError(f"{model}.{row.name}: derivative of {row.derivative!r}, which is not a Real of the table")

    def instantiation_token(self, version: str) -> str:
        """The identity of every FMU of this model at the package's ``version``: the FMI 2.0 ``guid`` and
        the FMI 3.0 ``instantiationToken`` of the pythonfmu FMU and of the native FMI 2.0 and 3.0 ones
        (the one function the build writes them with), which a host passes back at instantiation and the
        C front compares. A GUID, ``{xxxxxxxx-xxxx-8xxx-xxxx-xxxxxxxxxxxx}``: the first 16 bytes of the
        sha256 of the table's canonical text, marked as an RFC 9562 version-8 (custom) UUID. The text
        is JSON (sorted keys, no spaces, ASCII, floats as Python's repr, inf as Infinity) of the model's
        name and description, ``version``, every field of every row in value-reference order (what
        hosts see of a variable and what the FMU's state holds) and the base units of the units used;
        so the token is the same in every build of the same table and version, and changes with any of
        them. The model's ``constants`` (material presets: values, not interface) are not part of it."""
        units = sorted({row.unit for row in self.rows if row.unit is not None})
        text = json.dumps({"model": self.model, "description": self.description, "version": version,
                           "rows": [asdict(row) for row in self.rows],
                           "units": {unit: UNITS.get(unit) for unit in units}},
                          sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=True)
        digest = bytearray(hashlib.sha256(text.encode("ascii")).digest()[:16])
        digest[6] = (digest[6] & 0x0F) | 0x80  # version 8: a custom UUID (RFC 9562)
        digest[8] = (digest[8] & 0x3F) | 0x80  # the RFC variant
        return "{" + str(uuid.UUID(bytes=bytes(digest))) + "}"

    def __getitem__(self, name: str) -> Variable:
        return self._by_name[name]

    def __contains__(self, name: str) -> bool:
        return name in self._by_name

    def __iter__(self):
        return iter(self.rows)

    def __len__(self):
        return len(self.rows)

    @property
    def settable(self) -> tuple[Variable, ...]:
        """The inputs and parameters, in value-reference order."""
        return tuple(row for row in self.rows if row.causality in ("parameter", "input"))

    @property
    def outputs(self) -> tuple[Variable, ...]:
        return tuple(row for row in self.rows if row.causality == "output")

    @property
    def inputs(self) -> tuple[Variable, ...]:
        """The inputs, in value-reference order (what a feedthrough output depends on)."""
        return tuple(row for row in self.rows if row.causality == "input")

    @property
    def initial_unknowns(self) -> tuple[Variable, ...]:
        """What the modelDescription's InitialUnknowns list, in value-reference order: the outputs, the
        state derivatives and the calculated parameters."""
        return tuple(sorted(self.outputs + self.derivatives + self.calculated, key=lambda row: row.vr))

    @property
    def calculated(self) -> tuple[Variable, ...]:
        """The calculated parameters, in value-reference order."""
        return tuple(row for row in self.rows if row.causality == "calculatedParameter")

    @property
    def derivatives(self) -> tuple[Variable, ...]:
        """The derivatives of the continuous states (model exchange), in value-reference order."""
        return tuple(row for row in self.rows if row.derivative is not None)

    @property
    def continuous_states(self) -> tuple[Variable, ...]:
        """The continuous states, in the order of :attr:`derivatives` (the order of the state vector)."""
        return tuple(self._by_name[row.derivative] for row in self.derivatives)

    @property
    def event_indicators(self) -> tuple[Variable, ...]:
        """The event indicators (model exchange), in value-reference order."""
        return tuple(row for row in self.rows if row.event_indicator)

    @property
    def enumerations(self) -> dict[str, Variable]:
        """Enumeration type name -> the first variable declared with it (its items are the type's)."""
        out = {}
        for row in self.rows:
            if row.enumeration is not None:
                out.setdefault(row.enumeration, row)
        return out

    @property
    def choices(self) -> dict[str, dict[str, int]]:
        """FMU name -> {word: code} of every Integer-coded choice."""
        return {row.name: row.codes for row in self.rows if row.choices is not None}

    def key_of(self, name: str) -> str:
        return self._by_name[name].key

    def by_key(self, causalities=("parameter", "input")) -> dict[str, Variable]:
        """Package keyword (or result field) -> variable, for the given causalities."""
        return {row.key: row for row in self.rows if row.causality in causalities}
