"""Small pythonfmu FMUs the tests build from a slave source: a different FMU next to the project's,
or one with a deliberate bug."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path


def build_toy_fmu(work: Path, module: str, source: str, model: str) -> Path:
    """``work/<model>.fmu`` built by pythonfmu from ``source`` (saved as ``<module>.py``; a unique
    module name: FMU scripts sharing one clash in a process), with the project's guard in front of
    pythonfmu's binary, as every project FMU has (a plain pythonfmu 0.7 binary also frees its static
    PyState twice at process exit, which can abort the test process)."""
    from restitution.fmu.build_guard import make_standalone

    script = work / f"{module}.py"
    script.write_text(textwrap.dedent(source))
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(script), "-d", str(work)],
                   check=True, cwd=work, capture_output=True)
    fmu = work / f"{model}.fmu"
    make_standalone(fmu)
    return fmu
