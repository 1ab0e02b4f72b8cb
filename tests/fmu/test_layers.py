"""The imports between the parts of the FMU package show its layers, bottom up: the interface table's row
type; the models (their tables, slaves, backends and prose) and the C physics; the describers (every text
written from a table); the builders; the entry points. No part imports one above it, so a builder can be
replaced without touching what describes an FMU, and nothing a pythonfmu FMU bundles (the tables) reaches
the build. Among the host tools, the co-simulation helpers import neither sweeps nor scenes, and scenes do
not borrow from sweeps.

Read from the source with ``ast`` (every ``import`` and ``from ... import``, at any depth, lazy ones
included), never by importing."""
import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "fmu_src" / "restitution"
FMU = PACKAGE / "fmu"
#: The layer of each part of restitution.fmu (a subpackage, or a module at its top); higher imports lower.
LAYERS = {"table": 0, "physics_c": 1, "pythonfmu_guard": 1, "models": 1, "describe": 2, "ssp": 2, "compat": 2, "builders": 3, "__init__": 4, "__main__": 4}


def _imports(path: Path, package: str) -> set[str]:
    """The absolute dotted names ``path`` (a module of ``package``) imports."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                stem = ".".join(base + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            found.add(stem)
            found |= {f"{stem}.{alias.name}" for alias in node.names}
    return found


def _module_package(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts if path.name == "__init__.py" else parts[:-1])


def _part(dotted: str) -> str | None:
    """The part of restitution.fmu a dotted name belongs to, or None outside it."""
    parts = dotted.split(".")
    if parts[:2] != ["restitution", "fmu"] or len(parts) < 3:
        return None
    return parts[2] if parts[2] in LAYERS else None


def _fmu_modules():
    return sorted(p for p in FMU.rglob("*.py") if "__pycache__" not in p.parts)


def test_every_part_of_the_fmu_package_has_a_layer():
    parts = {p.relative_to(FMU).parts[0].removesuffix(".py") for p in _fmu_modules()}
    assert parts <= set(LAYERS), parts - set(LAYERS)


@pytest.mark.parametrize("path", _fmu_modules(), ids=lambda p: p.relative_to(FMU).as_posix())
def test_no_import_points_up(path):
    own = path.relative_to(FMU).parts[0].removesuffix(".py")
    upward = sorted(name for name in _imports(path, _module_package(path))
                    if (part := _part(name)) is not None and part != own and LAYERS[part] >= LAYERS[own]
                    and not (own in ("__init__", "__main__") and part in ("__init__", "__main__")))
    assert not upward, f"{path.relative_to(FMU)} ({own}, layer {LAYERS[own]}) imports {upward}"


def test_the_models_never_reach_the_describers_or_builders():
    """What a pythonfmu FMU bundles (the tables) and the models' own code import nothing of the build."""
    for path in (FMU / "models").rglob("*.py"):
        names = _imports(path, _module_package(path))
        assert not {n for n in names if _part(n) in ("describe", "builders")}, path


@pytest.mark.parametrize("tool, forbidden", [("cosim", ("sweep", "scene")), ("scene", ("sweep",))])
def test_host_tools_do_not_borrow_from_tools_above_them(tool, forbidden):
    for path in sorted((PACKAGE / tool).rglob("*.py")):
        names = _imports(path, _module_package(path))
        bad = sorted(n for n in names if n.split(".")[:2] in (["restitution", f] for f in forbidden))
        assert not bad, f"{path.relative_to(PACKAGE)} imports {bad}"
