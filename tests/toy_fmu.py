"""The tests' small pythonfmu FMUs, built from their slave scripts in tests/toys/ (one file each, with a
module name of its own: FMU scripts sharing one clash in a process): ToyGain (``toy_gain_slave``), a
different FMU next to the project's with a deliberate bug, and GuardToyInterrupt
(``toy_interrupt_slave``), Python work in every call."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

TOYS = Path(__file__).resolve().parent / "toys"


def build_plain_toy(work: Path, module: str) -> Path:
    """``work/<Model>.fmu`` as pythonfmu builds it from ``tests/toys/<module>.py`` (no guard)."""
    work.mkdir(parents=True, exist_ok=True)
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(TOYS / f"{module}.py"), "-d", str(work)],
                   check=True, cwd=work, capture_output=True)
    fmus = sorted(work.glob("*.fmu"))
    if len(fmus) != 1:
        raise RuntimeError(f"expected one FMU in {work}, found {fmus}")
    return fmus[0]


def build_toy_fmu(work: Path, module: str) -> Path:
    """The toy FMU with the project's guard in front of pythonfmu's binary, as every project FMU has (a
    plain pythonfmu 0.7 binary also frees its static PyState twice at process exit, which can abort the
    test process)."""
    from restitution.fmu.builders.guard import add_guard

    fmu = build_plain_toy(work, module)
    add_guard(fmu)
    return fmu
