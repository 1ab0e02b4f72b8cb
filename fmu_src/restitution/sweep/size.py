"""The size guard: what a sweep's table takes in memory and on disk, decided from the axis sizes
before any work; a table over the memory budget is streamed to disk, or the sweep refused with the
numbers (:class:`~restitution.sweep.spec.SizeError`)."""
from __future__ import annotations

import contextlib
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from .spec import OUTPUTS as _OUTPUT_TYPES, SizeError, SweepSpec
from .table import COLUMNS

__all__ = ["table_bytes", "output_bytes", "memory_budget", "SizePlan", "check_memory", "plan_size",
           "check_case_numbers", "format_bytes"]

def table_bytes(n_cases: int, columns=None) -> int:
    """Bytes the table of ``n_cases`` cases takes in memory (8 bytes a number, 1 a Boolean, a
    pointer for the pair label), for ``columns`` (None: all of :data:`COLUMNS`). Python ints."""
    names = COLUMNS if columns is None else [c for c in COLUMNS if c in columns]
    booleans = {"ok", *(name for name, _, vtype in _OUTPUT_TYPES if vtype == "Boolean")}
    per_case = sum(1 if name in booleans else 8 for name in names)
    return int(n_cases) * per_case


def output_bytes(n_cases: int, columns=None, suffix: str = ".csv", label: int = 40) -> int:
    """Upper estimate of the size of the written table: CSV text (a float's repr is at most 24
    characters, ``label`` characters for the pair) or Parquet (about the table in memory). Python ints."""
    if suffix.lower() == ".parquet":
        return table_bytes(n_cases, columns)
    names = COLUMNS if columns is None else [c for c in COLUMNS if c in columns]
    booleans = {"ok", *(name for name, _, vtype in _OUTPUT_TYPES if vtype == "Boolean")}
    per_case = sum(6 if name in booleans else label + 1 if name == "pair" else 25 for name in names)
    return int(n_cases) * per_case


def memory_budget(fraction: float = 0.5) -> int:
    """Default memory budget of a sweep table [bytes]: ``fraction`` of the memory available now
    (MemAvailable on Linux, else of the physical memory)."""
    available = None
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    available = int(line.split()[1]) * 1024
    if available is None:
        try:
            available = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (ValueError, OSError, AttributeError):
            available = 4 * 2**30
    return int(available * fraction)


@dataclass
class SizePlan:
    """Where a sweep's table goes: in memory (``stream`` false) or streamed to disk chunk by chunk."""

    n_cases: int
    memory: int  #: bytes the table(s) take in memory
    budget: int  #: the memory budget [bytes]
    stream: bool = False  #: over the budget, but fits on disk: kept on disk, never gathered
    disk: int = 0  #: bytes needed on disk when streaming (finished chunks + the written table)
    disk_free: int = 0  #: bytes free where the table is written

    def describe(self) -> str:
        text = f"the table would take {format_bytes(self.memory)} in memory"
        if not self.stream:
            text += f", within the memory budget of {format_bytes(self.budget)}"
        else:
            text += (f", over the memory budget of {format_bytes(self.budget)}: it is streamed to disk chunk by chunk "
                     f"(needs {format_bytes(self.disk)} on disk, {format_bytes(self.disk_free)} free) and never gathered")
        return text


def check_case_numbers(spec: SweepSpec) -> None:
    """Case numbers are 64-bit integers in the table: :class:`SizeError` for 2**63 cases or more."""
    if spec.n_cases >= 2 ** 63:
        raise SizeError(f"{spec.n_cases:,} cases: case numbers are 64-bit integers, at most "
                        f"{2 ** 63 - 1:,} cases a sweep")


def check_memory(spec: SweepSpec, columns=None, budget: int | None = None, backends: int = 1) -> int:
    """Bytes the table(s) will take; :class:`SizeError` with the numbers when above ``budget``
    (default :func:`memory_budget`) or when an axis is too long to build. Called before any work."""
    spec.check_axes()
    return plan_size(spec, columns, budget, backends=backends).memory


def plan_size(spec: SweepSpec, columns=None, budget: int | None = None, backends: int = 1, out=None,
              parts=None) -> SizePlan:
    """The size guard, from the axis sizes alone (nothing is built): a :class:`SizePlan`, or
    :class:`SizeError` with the numbers. A table over the memory budget (default
    :func:`memory_budget`) is streamed to disk when ``out`` (the table's path) is given, one back
    end runs and the finished chunks plus the written table fit in the free space there."""
    check_case_numbers(spec)
    need = backends * table_bytes(spec.n_cases, columns)
    budget = memory_budget() if budget is None else int(budget)
    plan = SizePlan(spec.n_cases, need, budget)
    if need <= budget:
        return plan
    refused = (f"the table of {spec.n_cases:,} cases would take {format_bytes(need)}, over the memory budget "
               f"of {format_bytes(budget)}")
    advice = "sweep fewer cases, keep fewer --columns, or raise --memory-budget"
    if out is None:
        raise SizeError(f"{refused}: {advice}")
    if backends > 1:
        raise SizeError(f"{refused}; --backend both compares the two tables in memory: {advice}, "
                        f"or run each back end on its own")
    out = Path(out)
    where = next((d for d in (out.parent.resolve(), *out.parent.resolve().parents) if d.exists()), Path("/"))
    free = shutil.disk_usage(where).free
    disk = table_bytes(spec.n_cases, columns) + output_bytes(
        spec.n_cases, columns, out.suffix, label=max([len(p) for p in spec.pairs] + [0]))
    if parts is not None and Path(parts).exists():  # resuming: what is there already counts as free
        free += sum(f.stat().st_size for f in Path(parts).rglob("*") if f.is_file())
    if disk > free:
        raise SizeError(f"{refused}, and streamed to disk it would need {format_bytes(disk)} in {where} "
                        f"({format_bytes(free)} free): {advice}")
    plan.stream, plan.disk, plan.disk_free = True, disk, free
    return plan


def format_bytes(n: int) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:,.3g} {unit} ({n:,} bytes)"
    return f"{n} bytes"
