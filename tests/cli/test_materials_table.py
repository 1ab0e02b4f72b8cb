"""The material presets as users see them: docs/materials.md is the generator's output, the terminal
table shows every preset with its values as stored, and look-alike keys are explained."""
import subprocess
import sys
from pathlib import Path

import pytest

from restitution.materials import ALIASES, MATERIALS
from restitution.materials_table import markdown, text

ROOT = Path(__file__).resolve().parents[2]
PRESETS = [key for key in MATERIALS if key not in ALIASES]


def test_docs_materials_md_is_the_generated_table():
    doc = (ROOT / "docs" / "materials.md").read_text(encoding="utf-8")
    assert doc == markdown(), "docs/materials.md is stale: python -m restitution.materials_table --markdown > docs/materials.md"


@pytest.mark.parametrize("key", PRESETS)
def test_each_preset_row_reads_back_as_its_values(key):
    """The printed numbers are the preset's own (E in GPa, Sy in MPa: exact decimal scalings)."""
    row = next(line.split() for line in text().splitlines() if line.split()[:1] == [key])
    m = MATERIALS[key]
    rho, sy, nu, e = row[-1], row[-2], row[-3], row[-4]
    assert float(e) * 1e9 == pytest.approx(m.E, rel=1e-15)
    assert float(nu) == m.nu and float(rho) == m.rho
    assert sy == "brittle" if m.brittle else float(sy) * 1e6 == pytest.approx(m.Sy, rel=1e-15)
    assert m.source and f"{key}: {m.source}" in text()


def test_aliases_are_explained_not_listed_twice():
    table = text()
    for alias, (key, _why) in ALIASES.items():
        assert MATERIALS[alias] is MATERIALS[key]
        rows = table.split("\n\nsources:")[0].splitlines()
        assert not any(line.split()[:1] == [alias] for line in rows)
        assert f"{alias} is another key for {key}" in table
    assert "borosilicate_glass and borosilicate_glass_t1" in table


def test_command_and_sweep_list_print_the_table():
    for cmd in ([sys.executable, "-m", "restitution.materials_table"],
                [sys.executable, "-m", "restitution.sweep", "--list"]):
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
        for key in PRESETS:
            assert any(line.split()[:1] == [key] and MATERIALS[key].name in line for line in out.splitlines()), (cmd, key)
