#!/usr/bin/env python3
"""Planted mutants: realistic mistakes, each planted in a staging copy of the project, and the tests that
must catch it. Where mutmut (build_scripts/mutation_test.sh) makes thousands of small syntactic mutants of
the physics modules, each mutant here is one hand-written mistake of a KIND that once went unnoticed (a
likelihood scaled by the variance, a correlation compared by its sign, a 90 % interval called 95 %, an onset
one sample late, Student's t at n degrees of freedom, ...), with the test files written to catch that kind.

For each mutant: copy the project's sources and tests into a temporary directory (once), replace the exact
old text by the new one in the copy (the old text must occur exactly once: "mutant text not found" or
"found N times" is a failure, not a crash: the code may have moved on, and the entry must follow it), run
the mutant's test files there with this Python (``-p no:cacheprovider -n 0 -x -q``, PYTHONPATH = the copy's
fmu_src, which a guard plugin checks is where ``restitution`` is imported from), and restore the file. The
tests must pass on the unmutated copy first (the baseline), or a failure would prove nothing.

    .venv/bin/python build_scripts/planted_mutants.py              # every mutant; exit 1 unless all caught
    .venv/bin/python build_scripts/planted_mutants.py --list       # the mutants, their kinds and tests
    .venv/bin/python build_scripts/planted_mutants.py --only NAME [--only NAME ...] [--tests PATH ...] [--keep]

The working tree is never written to. Outcomes: caught (the tests fail: pytest's exit status 1, or 2 for a
mutant that breaks an import), SURVIVED, and the failures of the harness's own premises: mutant text not found
or ambiguous, test path not found, baseline fails, timeout, error. Exit status 0 only when every mutant is caught.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: What the staging copy holds (those present): the package, the tests and what they read.
STAGED = ("fmu_src", "tests", "build_scripts", "examples", "docs", "requirements", "pyproject.toml", "README.md",
          "CHANGELOG.md", "LICENSE", "CITATION.cff")
#: Exit status of the guard plugin when ``restitution`` is not imported from the copy.
GUARD_STATUS = 97
GUARD = '''"""pytest plugin of planted_mutants.py: stop unless restitution is imported from the staging copy."""
import os
from pathlib import Path

import pytest


def pytest_sessionstart(session):
    import restitution

    stage = Path(os.environ["PLANTED_MUTANTS_STAGE"]).resolve()
    where = Path(restitution.__file__).resolve()
    if stage not in where.parents:
        pytest.exit(f"restitution imported from {where}, not from the staging copy {stage}", returncode=%d)
''' % GUARD_STATUS


@dataclass(frozen=True)
class Mutant:
    name: str
    file: str  # relative to the project root
    old: str
    new: str
    tests: tuple  # test paths, relative to the project root
    kind: str  # the KIND of mistake, one line


MUTANTS = (
    Mutant("known-sigma-variance", "fmu_src/restitution/fit/likelihood.py",
           "            return (self.data.v_out - m) / self.data.sigma\n",
           "            return (self.data.v_out - m) / self.data.sigma ** 2\n",
           ("tests/fit/test_known_sigma_interval.py",),
           "a likelihood weighing residuals by the wrong power of the known noise (intervals too narrow, "
           "same estimate)"),
    Mutant("signed-correlation", "fmu_src/restitution/fit/identifiability.py",
           "abs(corr[j, k]) > CORRELATED", "corr[j, k] > CORRELATED",
           ("tests/fit/test_parameter_combinations.py",),
           "parameters grouped by their signed correlation, not its magnitude (anti-correlated pairs not reported)"),
    Mutant("posterior-90", "fmu_src/restitution/fit/posterior.py",
           "np.percentile(values, [2.5, 50.0, 97.5])", "np.percentile(values, [5.0, 50.0, 95.0])",
           ("tests/fit/test_posterior_level.py",),
           "a posterior interval at another level than it is called (90 % reported as 95 %)"),
    Mutant("onset-one-sample-late", "fmu_src/restitution/fit/recording.py",
           "        onset = int(above[start])\n", "        onset = int(above[start]) + 1\n",
           ("tests/fit/test_click_onsets.py",),
           "a click onset off by one sample (impact times shifted; a fit hides it in the time origin)"),
    Mutant("student-t-dof", "fmu_src/restitution/sweep/statistics.py",
           "_student_t975(np.array([n - 1]))", "_student_t975(np.array([n]))",
           ("tests/sweep/test_sweep_mean_interval.py",),
           "the mean's interval with Student's t at n instead of n - 1 degrees of freedom (too narrow at small n)"),
    Mutant("student-t-dof-groups", "fmu_src/restitution/sweep/statistics.py",
           'out["ci_half"] = _student_t975(n - 1)', 'out["ci_half"] = _student_t975(n)',
           ("tests/sweep/test_sweep_mean_interval.py",),
           "the same, in the per-grid-point statistics (many groups at once)"),
    Mutant("ball-indicator-apex-c", "fmu_src/restitution/fmu/models/bouncing_ball/rst_native_ball.c",
           "apex = h + v * v / (2.0 * g);", "apex = h + v * v / g;",
           ("tests/fmu/test_native_ball.py", "tests/fmu/test_model_exchange.py"),
           "the bouncing ball's contact indicator with the apex height doubled (native C)"),
    Mutant("ball-indicator-clamp-python", "fmu_src/restitution/fmu/models/bouncing_ball/bouncing_ball_slave.py",
           "    if not v > 0.0:\n        return h\n    apex = h + v * v / (2.0 * g)\n",
           "    apex = h + v * v / (2.0 * g)\n",
           ("tests/fmu/test_native_ball.py", "tests/fmu/test_model_exchange.py"),
           "the bouncing ball's contact indicator without its clamp to h while the ball falls (Python slave)"),
)


def _read(path: Path) -> str:
    """The text of ``path`` with its line ends as they are (written back byte for byte)."""
    with open(path, encoding="utf-8", newline="") as stream:
        return stream.read()


def stage_copy(stage: Path) -> None:
    """The project's sources and tests, without caches, into ``stage``; the guard plugin into stage/_guard."""
    for name in STAGED:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, stage / name,
                            ignore=shutil.ignore_patterns("__pycache__", "*.pyc", ".pytest_cache"))
        elif source.is_file():
            shutil.copy2(source, stage / name)
    (stage / "_guard").mkdir()
    (stage / "_guard" / "planted_mutants_guard.py").write_text(GUARD)


def run_tests(stage: Path, tests, timeout: float) -> tuple[int | None, str, float]:
    """(pytest's exit status or None on timeout, its output's tail, CPU seconds of the children) of ``tests``
    in the copy."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(stage / "fmu_src"), str(stage / "_guard")]),
           "PLANTED_MUTANTS_STAGE": str(stage), "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("PYTEST_ADDOPTS", None)
    command = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-p", "planted_mutants_guard", "-n", "0",
               "-x", "-q", *tests]
    before = os.times()
    try:
        done = subprocess.run(command, cwd=stage, env=env, capture_output=True, text=True, timeout=timeout)
        status, output = done.returncode, done.stdout + done.stderr
    except subprocess.TimeoutExpired as exc:
        partial = exc.stdout or ""
        status, output = None, partial.decode(errors="replace") if isinstance(partial, bytes) else partial
    after = os.times()
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return status, "\n".join(output.strip().splitlines()[-15:]), cpu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", action="append", metavar="NAME", help="run this mutant only (repeatable)")
    parser.add_argument("--list", action="store_true", help="list the mutants and exit")
    parser.add_argument("--tests", action="append", metavar="PATH",
                        help="run these test paths (repeatable) instead of each mutant's own: to try new tests")
    parser.add_argument("--keep", action="store_true", help="keep the staging copy (its path is printed)")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds for one test run (default 1800)")
    parser.add_argument("-v", "--verbose", action="store_true", help="print pytest's output for every run")
    args = parser.parse_args(argv)

    mutants = MUTANTS
    if args.only:
        unknown = sorted(set(args.only) - {m.name for m in MUTANTS})
        if unknown:
            parser.error(f"unknown mutant(s) {', '.join(unknown)}: one of {', '.join(m.name for m in MUTANTS)}")
        mutants = tuple(m for m in MUTANTS if m.name in args.only)
    if args.tests:
        mutants = tuple(replace(m, tests=tuple(args.tests)) for m in mutants)
    if args.list:
        for m in mutants:
            print(f"{m.name}\n  kind:  {m.kind}\n  file:  {m.file}\n  tests: {' '.join(m.tests)}")
        return 0

    stage = Path(tempfile.mkdtemp(prefix="planted_mutants-"))
    results = []
    try:
        stage_copy(stage)
        print(f"staging copy: {stage} (python {sys.executable})", flush=True)
        baseline = {}
        for m in mutants:
            target = stage / m.file
            original = _read(target) if target.is_file() else None
            count = 0 if original is None else original.count(m.old)
            if count != 1:
                where = "file not found" if original is None else (
                    "mutant text not found" if count == 0 else f"mutant text found {count} times (ambiguous)")
                results.append((m, where, 0.0))
                print(f"{m.name}: {where} in {m.file}", flush=True)
                continue
            missing = [t for t in m.tests if not (stage / t.split("::")[0]).exists()]
            if missing:
                outcome = f"test path not found: {' '.join(missing)}"
                results.append((m, outcome, 0.0))
                print(f"{m.name}: {outcome}", flush=True)
                continue
            if m.tests not in baseline:  # the tests must pass on the unmutated copy
                status, tail, cpu = run_tests(stage, m.tests, args.timeout)
                baseline[m.tests] = (status, tail)
                print(f"baseline of {' '.join(m.tests)}: exit status {status} ({cpu:.1f} s CPU)", flush=True)
                if status != 0 or args.verbose:
                    print(tail, flush=True)
            status0, _tail0 = baseline[m.tests]
            if status0 != 0:
                outcome = "error: the guard stopped the baseline" if status0 == GUARD_STATUS else \
                    f"baseline fails (exit status {status0}): the tests fail without the mutant"
                results.append((m, outcome, 0.0))
                print(f"{m.name}: {outcome}", flush=True)
                continue
            target.write_text(original.replace(m.old, m.new), encoding="utf-8", newline="")
            try:
                status, tail, cpu = run_tests(stage, m.tests, args.timeout)
            finally:
                target.write_text(original, encoding="utf-8", newline="")
            if status in (1, 2):
                outcome = "caught" if status == 1 else "caught (the tests could not be collected)"
            elif status == 0:
                outcome = "SURVIVED"
            elif status is None:
                outcome = f"timeout after {args.timeout:g} s"
            elif status == GUARD_STATUS:
                outcome = "error: restitution was not imported from the staging copy"
            else:
                outcome = f"error: pytest exit status {status}"
            results.append((m, outcome, cpu))
            print(f"{m.name}: {outcome} ({cpu:.1f} s CPU)", flush=True)
            if args.verbose or not outcome.startswith("caught"):
                print(tail, flush=True)
    finally:
        if args.keep:
            print(f"kept: {stage}")
        else:
            shutil.rmtree(stage, ignore_errors=True)

    print(f"\nplanted mutants, {time.strftime('%Y-%m-%d')}:")
    width = max(len(m.name) for m, _, _ in results) if results else 0
    for m, outcome, cpu in results:
        print(f"  {m.name:<{width}}  {outcome:<40}  {m.kind}")
    caught = sum(outcome.startswith("caught") for _, outcome, _ in results)
    print(f"{caught} of {len(results)} caught")
    return 0 if caught == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
