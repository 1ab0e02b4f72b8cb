"""Build the project's FMUs into dist/ (or --out DIR): a thin entry point to
``python -m restitution.fmu build`` (see :mod:`restitution.fmu.builders`)."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "fmu_src"))  # works before `pip install` too

from restitution.fmu.__main__ import main  # noqa: E402

if __name__ == "__main__":
    argv = sys.argv[1:]
    if "--out" not in argv and not any(a.startswith("--out=") for a in argv):
        argv += ["--out", str(Path(__file__).resolve().parent.parent / "dist")]
    sys.exit(main(["build", *argv]))
