"""``restitution cor`` and the ``restitution`` command, as a user runs them (child processes): one COR
against an independent computation, units, refusals in one line with exit 2, the JSON."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from independent import apparent_cor, table_material

ARGS = ["--sphere", "s2_tool_steel", "--d", "6.35 mm", "--plate", "al_6061", "--t", "3 mm", "--v", "2 m/s"]


def _run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "restitution", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=120)


def test_cor_agrees_with_an_independent_computation(tmp_path):
    """e as printed and in the JSON equals Eq. (20) computed from the printed equations in mpmath with
    Zener's ODE solved by the tests (tests/independent.py, the materials from the paper's tables), to 6e-4:
    the exact method's table is accurate to ~1e-8 in e_ze, e45 is the printed formula, so the
    difference is the 4 printed digits' rounding (5e-5) plus that, far below 6e-4."""
    out = tmp_path / "cor.json"
    done = _run("cor", *ARGS, "--json", str(out))
    assert done.returncode == 0, done.stderr
    want = apparent_cor({k: float(x) for k, x in table_material("s2_tool_steel").items()},
                        {k: float(x) for k, x in table_material("al_6061").items()}, 6.35e-3, 3e-3, 2.0)
    first = done.stdout.splitlines()[0]
    assert first.startswith("e = ") and abs(float(first.split()[2]) - want) <= 6e-4, (first, want)
    data = json.loads(out.read_text())
    assert abs(data["result"]["e"] - want) <= 6e-4
    assert data["inputs"]["plate_t"] == pytest.approx(3e-3, rel=1e-15) and data["units"]["t_contact"] == "s"
    for name in ("e_ep", "e_ze", "v_rebound", "valid", "lambda_in_range", "vstar_in_range"):
        assert name in done.stdout or name.replace("lambda_in_range", "lambda <= 1.5").replace(
            "vstar_in_range", "V* <= 1000") in done.stdout, name
    assert "m/s" in done.stdout and " s " in done.stdout


def test_a_unit_and_si_give_the_same_case():
    with_unit, bare = _run("cor", *ARGS), _run("cor", *[a if a != "3 mm" else "0.003" for a in ARGS])
    assert with_unit.returncode == bare.returncode == 0
    assert with_unit.stdout.splitlines()[1:] == bare.stdout.splitlines()[1:]


def test_the_edge_monitor_takes_a_distance_with_a_unit():
    """--edge 76.2 mm: the P-wave echo (2 a / c_L, c_L of Al 6061 from its Lame constants) over the contact time
    the same command prints, to the 6 printed digits."""
    done = _run("cor", *ARGS, "--edge", "76.2 mm")
    assert done.returncode == 0, done.stderr
    lines = {line.split(" = ")[0].strip(): line for line in done.stdout.splitlines() if " = " in line}
    t_contact = float(lines["t_contact"].split()[2])
    E, nu, rho = (float(table_material("al_6061")[k]) for k in ("E", "nu", "rho"))
    c_l = ((E * nu / ((1 + nu) * (1 - 2 * nu)) + E / (1 + nu)) / rho) ** 0.5
    assert float(lines["edge_echo"].split()[2]) == pytest.approx(2 * 0.0762 / c_l / t_contact, rel=2e-5)
    assert "wave_delay" in lines and "concurrent" in lines["wave_delay"]
    unbounded = _run("cor", *ARGS)
    assert "an unbounded plate" in unbounded.stdout


@pytest.mark.parametrize("change, words", [
    (("--v", "-1 m/s"), ["--v", "v_approach", "outside"]),
    (("--v", "2e5"), ["--v", "v_approach", "outside"]),
    (("--t", "3 GPa"), ["--t", "plate.t", "length"]),
    (("--d", "six"), ["--d", "sphere.d", "not a number"]),
    (("--sphere", "chrome_stel"), ["--sphere", "chrome_steel"]),
    (("--plate", "unobtainium"), ["--plate", "unknown material"]),
    (("--edge", "-3 mm"), ["--edge", "plate.edge_distance", "outside"]),
])
def test_bad_input_is_one_line_and_exit_2(change, words):
    args = list(ARGS) + (["--edge", "1 m"] if change[0] == "--edge" else [])
    args[args.index(change[0]) + 1] = change[1]
    done = _run("cor", *args)
    assert done.returncode == 2 and done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and all(w in lines[0] for w in words), done.stderr


def test_json_into_a_directory_is_refused(tmp_path):
    done = _run("cor", *ARGS, "--json", str(tmp_path))
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1 and "--json" in done.stderr


def test_the_restitution_command_lists_and_dispatches():
    usage = _run()
    assert usage.returncode == 2 and all(name in usage.stdout for name in ("cor", "sweep", "scene", "materials", "fmu"))
    wrong = _run("cr")
    assert wrong.returncode == 2 and "did you mean cor" in wrong.stderr
    materials = _run("materials")
    assert materials.returncode == 0 and "al_6061" in materials.stdout
    version = _run("--version")
    assert version.returncode == 0 and version.stdout.startswith("restitution ")


@pytest.mark.parametrize("option", ["--v", "--d", "--sphere", "--zener-method"])
def test_a_huge_value_is_echoed_shortened(option):
    """A 100 000-character value is refused in one short line: the first 60 characters, an ellipsis and
    its length (it was echoed whole)."""
    huge = "7" + "x" * 99_999
    args = list(ARGS) + ([option, huge] if option not in ARGS else [])
    if option in ARGS:
        args[args.index(option) + 1] = huge
    done = _run("cor", *args)
    line = done.stderr.strip().splitlines()[-1]
    assert done.returncode == 2 and done.stdout == "" and option in line, done.stderr[:300]
    assert len(done.stderr) < 1000 and "(100000 characters)" in line and "7" + "x" * 59 + "..." in line, line


def test_standard_output_on_a_full_disk_is_one_line_and_exit_74():
    """stdout on /dev/full: ENOSPC when the result is flushed; one line on stderr, exit 74, no traceback and
    no "Exception ignored" at the interpreter's exit."""
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "restitution", "cor", *ARGS], stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=120)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 74 and len(lines) == 1, done.stderr
    assert lines[0].startswith("restitution cor: error: ") and "standard output" in lines[0] and "ENOSPC" in lines[0]


@pytest.mark.parametrize("command", ["cor", "fit"])
def test_help_on_a_full_disk_is_one_line_and_exit_74(command):
    """--help with stdout on /dev/full: argparse printed the help and exited 0, then the interpreter's
    final flush failed ("Exception ignored ... OSError"); now one line on stderr and exit 74."""
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "restitution", command, "--help"], stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=120)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 74 and len(lines) == 1, done.stderr
    assert lines[0].startswith(f"restitution {command}: error: ") and "ENOSPC" in lines[0], lines
