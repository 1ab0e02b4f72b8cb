"""docs/assumptions.md against the code it describes: the monitor table is the output of
examples/assumptions_table.py, every variable, field and object the page names exists, its
wave_delay thresholds are restitution.zener.WAVE_DELAY_LIMIT, and what it says about the table
and the FMU's messages holds. A page that drifts from the code fails here."""
import importlib
import importlib.util
import inspect
import re
import subprocess
import sys
from dataclasses import fields
from pathlib import Path

import pytest

import restitution
from restitution import zener
from restitution.assumptions import departures
from restitution.fmu.describe.common import log_categories
from restitution.fmu.models.sphere_plate_impact.variables import TABLE
from restitution.model import EFFECT_MODES, RESTITUTION_MODELS, ImpactResult, published

ROOT = Path(__file__).resolve().parents[2]
PAGE_PATH = ROOT / "docs" / "assumptions.md"
SCRIPT = ROOT / "examples" / "assumptions_table.py"
BEGIN, END = "<!-- assumptions_table.py -->", "<!-- end -->"
REGENERATE = f"paste the output of `{sys.executable} examples/assumptions_table.py` between the markers"


@pytest.fixture(scope="module")
def page() -> str:
    return PAGE_PATH.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def script():
    """examples/assumptions_table.py as a module, for the rows behind the printed table."""
    spec = importlib.util.spec_from_file_location("example_assumptions_table", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _sections(page: str) -> list[str]:
    """The page cut at its level-2 headings (each piece starts with its heading)."""
    return re.split(r"(?m)^(?=## )", page)


def _section(page: str, heading: str) -> str:
    found = [s for s in _sections(page) if s.startswith(f"## {heading}\n")]
    assert len(found) == 1, f"docs/assumptions.md has no single section '## {heading}'"
    return found[0]


# --- the table is the script's output ----------------------------------------------------------

def test_table_between_the_markers_is_the_script_output(page):
    # run as a user would (a subprocess, the script's own __main__), not through an import
    printed = subprocess.run([sys.executable, str(SCRIPT)], capture_output=True, text=True, check=True,
                             cwd=ROOT).stdout
    assert page.count(BEGIN) == 1 and page.count(END) == 1, "the page needs each marker exactly once"
    pasted = page.split(BEGIN, 1)[1].split(END, 1)[0]
    # the markers sit on their own lines around the output, which ends in a newline
    assert pasted == "\n" + printed, f"docs/assumptions.md's table is stale: {REGENERATE}"


# --- every name the page gives exists --------------------------------------------------------------

#: Names of the package a bare (undotted) backticked word may be: ImpactResult's fields and ``valid``,
#: restitution.impact's keywords, the option words, the material presets and their attributes.
PACKAGE_WORDS = ({f.name for f in fields(ImpactResult)} | {"valid"}
                 | set(inspect.signature(restitution.impact).parameters)
                 | set(zener.ZENER_METHODS) | set(RESTITUTION_MODELS) | set(EFFECT_MODES)
                 | set(restitution.MATERIALS) | {name for name in dir(restitution.Material) if not name.startswith("_")})
FMU_NAMES = {var.name for var in TABLE}
LOG_CATEGORIES = {node.get("name") for node in log_categories("fmi2")}
#: FMI's own API and status words (fmi2Reset, fmi3Warning): the standard's names, not the project's
FMI_WORD = re.compile(r"fmi[23][A-Z][A-Za-z]*")
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*")


def _backticked_names(page: str) -> set[str]:
    """Backticked words that look like a name (dotted or not). Code with spaces, calls or punctuation
    (a command line, a log message) is not a name and is left to the other tests."""
    return {token for token in re.findall(r"`([^`\n]+)`", page) if NAME.fullmatch(token)}


def _resolves(dotted: str) -> bool:
    """``restitution.x.y``: an attribute chain that imports (a module, or a module's attribute)."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def test_every_named_variable_field_and_object_exists(page):
    names = _backticked_names(page)
    unknown = []
    for name in sorted(names):
        if name.startswith("restitution."):
            ok = _resolves(name)
        elif "." in name:  # sphere.*, plate.*, zener.*, jgm.*, monitor.*: the FMU's naming
            ok = name in FMU_NAMES
        else:
            ok = (name in PACKAGE_WORDS or name in FMU_NAMES or name in LOG_CATEGORIES
                  or FMI_WORD.fullmatch(name) is not None)
        if not ok:
            unknown.append(name)
    assert not unknown, f"docs/assumptions.md names what does not exist: {unknown}"
    # the page must name every monitor, in the package and in the FMU (a renamed one fails above)
    for must in ("wave_delay", "concurrent", "edge_echo", "edge_clear", "lambda_in_range", "vstar_in_range",
                 "e_negative", "valid", "plate_edge_distance", "monitor.wave_delay", "monitor.concurrent",
                 "monitor.edge_echo", "monitor.edge_clear", "plate.edge_distance", "zener.in_range",
                 "jgm.in_range", "restitution.assumptions.AssumptionWarning", "restitution.cosim.bounce"):
        assert must in names, f"docs/assumptions.md does not name `{must}`"


def test_links_reach_files_and_headings(page):
    slugs = {re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
             for heading in re.findall(r"(?m)^#+ (.+)$", page)}
    for target in re.findall(r"\]\(([^)\s]+)\)", page):
        if target.startswith("#"):
            assert target[1:] in slugs, f"link to a missing heading: {target}"
        elif "://" not in target:
            assert (PAGE_PATH.parent / target.split("#")[0]).exists(), f"link to a missing file: {target}"


# --- the wave_delay threshold is the code's ------------------------------------------------------

#: A number stated as a bound: after a comparison, or after the word threshold
_BOUND = r"(?:≤|<=|≥|>=|<|>|above|below|exceeds)\s*([0-9]+(?:\.[0-9]+)?)"
#: ... right after the monitor's name: "`wave_delay` ≤ 1.8136", "monitor.wave_delay above 1.8136"
_NAMED_BOUND = re.compile(r"(?:monitor\.)?wave_delay`?\s*" + _BOUND)
_THRESHOLD = re.compile(r"threshold\s*(?:is|of|:|=)?\s*([0-9]+(?:\.[0-9]+)?)")


def _wave_delay_thresholds(page: str) -> list[str]:
    """Every threshold the page states for wave_delay: a bound written right after the name, anywhere;
    and "threshold X" in a section about wave_delay alone (one that does not name the edge monitor,
    whose own threshold is 1)."""
    found = _NAMED_BOUND.findall(page)
    for section in _sections(page):
        if "wave_delay" in section and "edge_echo" not in section:
            found += _THRESHOLD.findall(section)
    return found


def test_every_wave_delay_threshold_is_the_limit(page):
    found = _wave_delay_thresholds(page)
    # at least the overview row and the monitor's section state it
    assert len(found) >= 2, f"the page states no wave_delay threshold the test can find: {found}"
    assert {float(x) for x in found} == {zener.WAVE_DELAY_LIMIT}, found
    assert repr(zener.WAVE_DELAY_LIMIT) in found  # written as the code writes it, not rounded


def test_stated_wave_delays_are_the_exact_solution(page):
    """"1.36 at λ = 1": the delays the monitor's section quotes, to the digits it gives them."""
    section = _section(page, "Plastic and wave processes at the same time")
    stated = re.findall(r"(\d\.\d+)\s+at\s+λ\s*=\s*(\d(?:\.\d+)?)", section)  # a line may break between
    assert len(stated) >= 3, stated
    tau0_half_space = zener.zener_restitution(0.0)[1]
    for value, lam in stated:
        delay = zener.wave_delay(zener.zener_restitution(float(lam))[1], tau0_half_space)
        assert round(delay, len(value) - 2) == float(value), (value, lam, delay)


# --- what the page says about the table and the messages ---------------------------------------

def _cases(script, predicate) -> set:
    """(ball, d [mm], t [mm]) of the table's impacts where ``predicate(result)`` holds."""
    return {(row["ball"], round(row["d"] * 1e3, 2), round(row["t"] * 1e3, 2))
            for ball in script.BALLS for row in script.rows(ball) if predicate(row["result"])}


def test_the_observations_under_the_table_hold(script):
    steel, glass = script.BALLS
    thin = [1.6, 3.18, 4.76, 6.35]
    # "the edge echo comes back at about the time the ball leaves": the 6.35 mm steel ball up to t = 6.35 mm
    assert _cases(script, lambda res: not res.edge_clear) == {(steel, 6.35, t) for t in thin}
    echoes = [row["result"].edge_echo for ball in script.BALLS for row in script.rows(ball)]
    # "edge_echo lies between 0.51 and 1.84", as the table rounds
    assert (round(min(echoes), 2), round(max(echoes), 2)) == (0.51, 1.84)
    # "one impact leaves the studied range" and it is the one not concurrent
    assert _cases(script, lambda res: not res.valid) == {(steel, 6.35, 1.6)}
    assert _cases(script, lambda res: not res.concurrent) == {(steel, 6.35, 1.6)}
    # the two negative COR are the steel balls on the 1.6 mm plate; every glass impact is inside
    assert _cases(script, lambda res: res.e_negative) == {(steel, 4.76, 1.6), (steel, 6.35, 1.6)}
    flagged = _cases(script, lambda res: not (res.valid and res.concurrent and res.edge_clear) or res.e_negative)
    assert not {case for case in flagged if case[0] == glass}
    # "apart from the 1.6 mm plates, wave_delay stays below 1.1"
    assert _cases(script, lambda res: res.wave_delay >= 1.1) <= {(b, d, 1.6) for b in script.BALLS
                                                                  for d in (4.76, 6.35)}


def test_quoted_fmu_message_is_what_the_fmus_log(page, script):
    """A log line the page quotes is one restitution.assumptions writes for a case of the table
    (the FMUs, both kinds, write those words; tests/fmu compares them)."""
    quoted = [token for token in re.findall(r"`([^`\n]+)`", page) if re.search(r" is (?:above|below) ", token)]
    assert quoted, "the page quotes no FMU message"
    said = {message for ball in script.BALLS for row in script.rows(ball)
            for _name, message in departures(published(row["result"].as_dict()))}
    for line in quoted:
        assert line in said, f"not a message the FMUs log for the table's cases: {line}"
