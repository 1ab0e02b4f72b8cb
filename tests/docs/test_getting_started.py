"""docs/getting_started.md runs as printed: every shell and Python block, in the page's order, in one new
temporary folder, each in a child process (bash -e, or python), with the virtual environment's commands
first on PATH as ``. .venv/bin/activate`` puts them. Where a ``text`` block follows a block, the block
prints exactly that (a duration such as "0.049 s)" aside). So the page cannot rot: a renamed option, a
changed output or a moved file fails here.

Step 1 (install) is checked without downloading anything: its ``pip install`` line is resolved by pip
against the environment the tests run in (``--dry-run --no-index``: the project installs, every extra it
names exists), and its ``restitution fmu build --out dist`` is the session's build of every FMU
(``built_fmus``, the same ``build_all`` the command calls) linked as ``dist`` in the folder, after
``restitution fmu build --help`` confirms the option; rebuilding would only repeat a minute or two.
"""
import csv
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "getting_started.md"
BIN = Path(sys.executable).parent
BUILD_LINE = "restitution fmu build --out dist"


def _blocks() -> list[tuple[str, str]]:
    """The page's fenced blocks in order: (language, text)."""
    text = PAGE.read_text(encoding="utf-8")
    return [(m.group(1), m.group(2)) for m in re.finditer(r"(?ms)^```(\w*)\n(.*?)^```", text)]


def _same_output(printed: str) -> str:
    """Output as compared: a duration ("0.049 s)") masked."""
    return re.sub(r"\d+(\.\d+)? s\)", "<duration> s)", printed)


def _env(work: Path) -> dict:
    return {"PATH": f"{BIN}:/usr/bin:/bin", "HOME": str(work), "MPLBACKEND": "Agg", "LANG": "C.UTF-8",
            "VIRTUAL_ENV": str(BIN.parent)}


def test_page_has_the_five_steps():
    text = PAGE.read_text(encoding="utf-8")
    headings = re.findall(r"(?m)^## (.+)$", text)
    assert headings[:5] == ["1. Install", "2. One COR", "3. A fit to a drop test", "4. The FMU in fmpy", "5. A sweep"]
    languages = [language for language, _ in _blocks()]
    assert languages.count("python") >= 1 and languages.count("sh") >= 4
    assert all(language in ("sh", "python", "text") for language in languages), languages
    commands = "\n".join(code for language, code in _blocks() if language == "sh")
    for command in ("restitution cor ", "restitution fit ", "restitution sweep ", BUILD_LINE):
        assert command in commands


def test_install_block_resolves_offline(tmp_path):
    (install, *_), = [[code for language, code in _blocks() if language == "sh"]]
    assert "pip install" in install and BUILD_LINE in install
    (spec,) = re.findall(r'pip install -e "([^"]+)"', install)
    extras = re.fullmatch(r"\.\[([\w,-]+)\]", spec).group(1).split(",")
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert set(extras) <= set(declared), f"the page names extras pyproject.toml does not declare: {extras}"
    proc = subprocess.run([sys.executable, "-m", "pip", "install", "--dry-run", "--no-index", "--no-build-isolation",
                           "--quiet", "--disable-pip-version-check", "-e", spec], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    build_help = subprocess.run([str(BIN / "restitution"), "fmu", "build", "--help"], capture_output=True, text=True,
                                timeout=120)
    assert build_help.returncode == 0 and "--out" in build_help.stdout


@pytest.fixture(scope="module")
def ran(built_fmus, tmp_path_factory) -> Path:
    """The folder every block after step 1 ran in, in the page's order; each output checked on the way."""
    work = tmp_path_factory.mktemp("getting_started")
    (work / "dist").symlink_to(built_fmus, target_is_directory=True)  # step 1's build: the session's
    blocks = _blocks()
    first_shell = next(k for k, (language, _) in enumerate(blocks) if language == "sh")
    for k, (language, code) in enumerate(blocks):
        if k == first_shell or language == "text":
            continue
        if language == "python":
            script = work / f"block_{k}.py"
            script.write_text(code, encoding="utf-8")
            argv = [sys.executable, str(script)]
        else:
            argv = ["bash", "-e", "-c", code]
        proc = subprocess.run(argv, cwd=work, capture_output=True, text=True, env=_env(work), timeout=600)
        assert proc.returncode == 0, f"docs/getting_started.md block {k} ({language}) failed:\n{code}\n" \
                                     f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
        if k + 1 < len(blocks) and blocks[k + 1][0] == "text":
            assert _same_output(proc.stdout) == _same_output(blocks[k + 1][1]), \
                f"block {k} prints:\n{proc.stdout}\nthe page shows:\n{blocks[k + 1][1]}"
    return work


def test_every_block_runs_and_prints_what_the_page_shows(ran):
    assert (ran / "drops.csv").is_file()


def test_the_files_the_page_names_are_written(ran):
    assert (ran / "fit.png").stat().st_size > 10_000
    assert (ran / "map_cor_map.png").stat().st_size > 10_000
    with open(ran / "map.csv", newline="") as f:  # a column's name, its unit in brackets or not: "plate.t [m]"
        rows = [{key.split(" [")[0]: value for key, value in row.items()} for row in csv.DictReader(f)]
    assert len(rows) == 4 * 8  # four speeds x eight thicknesses
    # as the page says: 4 cases, the thinnest plate's, outside Zener's studied range
    outside = [row for row in rows if row["valid"] == "False"]
    assert len(outside) == 4 and {float(row["plate.t"]) for row in outside} == {1e-3}
    assert "4 cases (the thinnest plate)" in " ".join(PAGE.read_text(encoding="utf-8").split())


def test_the_fmu_and_the_command_agree():
    """Step 4's FMU prints the e of step 2's command (the same case)."""
    blocks = _blocks()
    cor_text = next(blocks[k + 1][1] for k, (language, code) in enumerate(blocks)
                    if language == "sh" and "restitution cor" in code)
    fmu_text = next(blocks[k + 1][1] for k, (language, _) in enumerate(blocks) if language == "python")
    e = re.match(r"e = (\S+)", cor_text).group(1)
    assert fmu_text.startswith(f"e = {e},")


def test_linked_first_from_the_site_and_from_readme():
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    toctree = re.search(r"(?ms)```\{toctree\}\n(.*?)```", index).group(1)
    entries = [line.strip() for line in toctree.splitlines() if line.strip() and not line.startswith(":")]
    assert entries[0] == "getting_started", entries
    first_link = re.search(r"\]\(([^)]+\.md)\)", index)
    assert first_link and first_link.group(1) == "getting_started.md"
    assert "(docs/getting_started.md)" in (ROOT / "README.md").read_text(encoding="utf-8")
