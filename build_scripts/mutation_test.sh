#!/usr/bin/env bash
# Mutation testing of the physics modules (jgm, zener, zener_exact, fusion, model, materials) with
# mutmut, configured in pyproject.toml ([tool.mutmut]). mutmut expects the package under src/, so
# the run happens in a staging copy, .mutation/ (fmu_src/restitution -> src/restitution, tests/,
# pyproject.toml). Prints the score and the surviving mutants; `cd .mutation && ../.venv/bin/mutmut
# show NAME` shows one. Takes tens of minutes on 2 cores.
#   bash build_scripts/mutation_test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python ] || bash build_scripts/quickstart.sh test --collect-only -q > /dev/null
stage=.mutation
rm -rf "$stage"
mkdir -p "$stage/src"
cp -r fmu_src/restitution "$stage/src/restitution"
find "$stage" -name __pycache__ -prune -exec rm -rf {} +
cp -r tests "$stage/tests"
cp pyproject.toml "$stage/"
cd "$stage"
../.venv/bin/mutmut run --max-children "${MUTMUT_JOBS:-2}" || true
../.venv/bin/mutmut results --all true > results.txt || true
../.venv/bin/python - <<'PY'
import collections, re
counts = collections.Counter()
survivors = []
for line in open("results.txt"):
    m = re.match(r"\s*(\S+): (.+)$", line)
    if m:
        counts[m.group(2).strip()] += 1
        if m.group(2).strip() == "survived":
            survivors.append(m.group(1))
total = sum(counts.values())
killed = counts.get("killed", 0)
print(f"mutants: {total}; " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
if total:
    print(f"score (killed / all): {killed / total:.1%}")
print("survivors:")
for name in survivors:
    print("  " + name)
PY
