"""Regenerate the pictures of docs/examples.md (docs/img/*.png) and print its tables.

    python examples/make_docs_figures.py [--fmu-dir dist] [--steps 1e-2 1e-3 1e-4 1e-5]

Runs every example with the same code the tests run, at dpi 90, writing into docs/img/.
Wall times depend on the machine and its load.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bouncing_ball  # noqa: E402
import paper_figures  # noqa: E402
import two_fmu_cosim  # noqa: E402

from restitution.fmu import default_fmu  # noqa: E402

DOCS_IMG = HERE.parent / "docs" / "img"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fmu-dir", type=Path, default=None, help="folder with both FMUs (default: dist/, built if missing)")
    parser.add_argument("--steps", type=float, nargs="+", default=[1e-2, 1e-3, 1e-4, 1e-5])
    parser.add_argument("--repeat", type=int, default=3, help="runs per master and step (shortest wall time kept)")
    args = parser.parse_args(argv)
    fmu_dir = args.fmu_dir or default_fmu(model="BouncingBall").parent
    impact = fmu_dir / "SpherePlateImpact.fmu"
    print("## bouncing_ball\n")
    bouncing_ball.run(fmu_path=impact, out_dir=DOCS_IMG, dpi=90)
    print("\n## two_fmu_cosim\n")
    two_fmu_cosim.run(steps=args.steps, fmu_dir=fmu_dir, out_dir=DOCS_IMG, osp_dir=HERE / "output" / "osp", dpi=90,
                      repeat=args.repeat)
    print("\n## paper_figures\n")
    paper_figures.run(fmu_path=impact, out_dir=DOCS_IMG, dpi=90)
    return 0


if __name__ == "__main__":
    sys.exit(main())
