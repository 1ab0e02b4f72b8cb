"""The imports of the package show its layers, bottom up (docs/layout.md):

* core: the physics (model, zener, jgm, fusion, ...), the materials, the domain, reading text with a
  unit and the one-line refusal of a user's value (units);
* tables: the interface tables (``fmu/table.py``, ``fmu/models/<model>/variables.py``), plain data the
  pythonfmu FMUs bundle;
* readers: an input's value by its name (inputs), the command lines' option declarations (options), the
  presets' table (materials_table);
* fmu: the rest of ``restitution.fmu`` (slaves, describers, builders);
* cosim: the co-simulation helpers;
* the tool wings: cor, fit, sweep, scene, export; each imports only from the layers below, never from
  another wing;
* top: the ``restitution`` command, which starts a wing by its name.

No module imports one above its layer, no wing imports a sibling, and the imports form no cycle. Inside
``restitution.fmu`` the parts have layers of their own: the interface table's row type; the models (their
tables, slaves, backends and prose) and the C physics; the describers (every text written from a table);
the builders; the entry points, so a builder can be replaced without touching what describes an FMU, and
nothing a pythonfmu FMU bundles (the tables) reaches the build.

Read from the source with ``ast`` (every ``import`` and ``from ... import``, at any depth, lazy ones
included), never by importing."""
import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "fmu_src" / "restitution"
FMU = PACKAGE / "fmu"
#: The layer of each part of restitution.fmu (a subpackage, or a module at its top); higher imports lower.
LAYERS = {"table": 0, "physics_c": 1, "pythonfmu_guard": 1, "models": 1, "describe": 2, "ssp": 2, "compat": 2, "installed": 2, "builders": 3, "__init__": 4, "__main__": 4}


def _imports(path: Path, package: str, modules=frozenset()) -> set[str]:
    """The absolute dotted names ``path`` (a module of ``package``) imports. ``from PACKAGE import a, b``
    where every name is a module of ``modules`` imports those modules, not the package's ``__init__``
    (which any import of a submodule runs anyway)."""
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
            names = {f"{stem}.{alias.name}" for alias in node.names}
            if not names <= modules:
                found.add(stem)
            found |= names
    return found


def _module_package(path: Path) -> str:
    """The package ``path``'s relative imports start from: its folder's (an ``__init__.py`` is its
    folder's package itself)."""
    return ".".join(path.relative_to(PACKAGE.parent).parts[:-1])


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


# --- the whole package ------------------------------------------------------------------------
#: The package's layers, bottom up: a module imports only from its own layer or one below.
PACKAGE_LAYERS = ("core", "tables", "readers", "fmu", "cosim", "wing", "top")
#: The tool wings (a module or a subpackage of restitution each): none imports another.
WINGS = ("cor", "fit", "sweep", "scene", "export")
#: Top-level modules above core, by layer (every other top-level module, and viz, is core).
_TOP_LEVEL = {"inputs": "readers", "options": "readers", "materials_table": "readers", "command": "top",
              "__main__": "top"}
#: Most modules on one chain of imports (lazy ones included): 17 before the wings were cut apart (the
#: cycles broken), 16 after impact(outputs=...) split the array steps out of model.py; then plain data sat
#: below the code using it (the result record, the option words, a sweep's columns), Zener's solvers side
#: by side (the ODE's large-lambda form from zener_exact, which imports nothing of the package), and the
#: sweep's table, statistics and plots read its columns, not its spec. Read right (a package's
#: ``__init__`` imports relative to itself: they had been dropped), the builders made it 14, 10 once they
#: sat side by side too: the plan chooses (with the compilers' flags and the products' names beside the
#: sources), ``products.run`` builds, and the tools import the builder they use, not the package's
#: ``__init__``. Chains of 10: sweep's __main__ -> compare -> backends -> spec -> values -> inputs -> the
#: interface table -> materials -> domain -> _num; scene's, through cosim; fit's, through the model
#: (docs/layout.md). A ratchet: a deeper chain fails.
MAX_DEPTH = 10


def package_layer(module: str) -> tuple[str, str | None]:
    """(layer of :data:`PACKAGE_LAYERS`, wing or None) of the dotted ``module`` of restitution."""
    parts = module.split(".")[1:]
    if not parts:
        return "core", None
    if parts[0] in WINGS:
        return "wing", parts[0]
    if parts[0] == "cosim":
        return "cosim", None
    if parts[0] == "fmu":
        if parts[1:] in (["table"], ["models"]) or (len(parts) >= 3 and parts[1] == "models"
                                                    and parts[3:] in ([], ["variables"])):
            return "tables", None
        return "fmu", None
    return _TOP_LEVEL.get(parts[0], "core"), None


def violations(graph: dict) -> list[str]:
    """Every import of ``graph`` (module -> the modules of restitution it imports) that points up a layer
    or sideways from one wing into another."""
    found = []
    for module, imported in sorted(graph.items()):
        layer, wing = package_layer(module)
        for target in sorted(imported):
            target_layer, target_wing = package_layer(target)
            if PACKAGE_LAYERS.index(target_layer) > PACKAGE_LAYERS.index(layer):
                found.append(f"{module} ({layer}) imports {target} ({target_layer})")
            elif wing and target_wing and wing != target_wing:
                found.append(f"{module} (wing {wing}) imports {target} (wing {target_wing})")
    return found


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if path.name == "__init__.py" else parts)


def package_graph() -> dict:
    """module -> the modules of restitution it imports (an imported name that is a module's attribute
    counts as its module), read from the source."""
    paths = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "__pycache__" not in p.parts}
    graph = {}
    for module, path in paths.items():
        names = _imports(path, _module_package(path), frozenset(paths))
        graph[module] = {n for n in names if n in paths and n != module}
    return graph


def cycles(graph: dict) -> list[list[str]]:
    """The import cycles of ``graph`` (its strongly connected components of more than one module)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in graph.get(node, ()):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.append(top)
                if top == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def depth(graph: dict) -> int:
    """Most modules on one chain of imports of an acyclic ``graph``."""
    memo = {}

    def chain(node):
        if node not in memo:
            memo[node] = 1 + max((chain(n) for n in graph.get(node, ())), default=0)
        return memo[node]

    return max(chain(n) for n in graph)


def test_every_import_of_the_package_points_down_and_no_wing_imports_another():
    assert violations(package_graph()) == []


#: A deliberate bad import (module, what it imports) -> the words of the rule's report.
BAD_IMPORTS = {
    ("restitution.sweep.statistics", "restitution.scene.explain"): "(wing sweep) imports restitution.scene.explain",
    ("restitution.cor", "restitution.fit.report"): "(wing cor) imports restitution.fit.report",
    ("restitution.export.writer", "restitution.sweep.table"): "(wing export) imports",
    ("restitution.cosim.bouncing", "restitution.scene.loader"): "(cosim) imports restitution.scene.loader (wing)",
    ("restitution.inputs", "restitution.sweep.values"): "(readers) imports restitution.sweep.values (wing)",
    ("restitution.units", "restitution.inputs"): "(core) imports restitution.inputs (readers)",
    ("restitution.fmu.table", "restitution.fmu.builders.plan"): "(tables) imports restitution.fmu.builders.plan (fmu)",
}


@pytest.mark.parametrize("bad", sorted(BAD_IMPORTS), ids="->".join)
def test_a_sideways_or_upward_import_fails_the_rule(bad):
    """The rule on the package's graph with one deliberate bad import added: it is reported."""
    graph = package_graph()
    module, imported = bad
    graph.setdefault(module, set()).add(imported)
    found = violations(graph)
    assert any(BAD_IMPORTS[bad] in line for line in found), found


def test_the_imports_form_no_cycle():
    assert cycles(package_graph()) == []


def test_a_cycle_is_found():
    graph = package_graph()
    graph["restitution.units"].add("restitution.materials")  # materials imports units: now a circle
    assert ["restitution.materials", "restitution.units"] in cycles(graph)


def test_a_packages_init_is_read_with_its_own_imports():
    """``restitution.fmu``'s ``__init__`` imports its builders (lazily, on first use), and the top
    package's imports the model: a package's relative imports start at its own folder."""
    graph = package_graph()
    assert "restitution.fmu.builders" in graph["restitution.fmu"]
    assert "restitution.model" in graph["restitution"]


def test_the_import_chains_are_no_deeper_than_the_ratchet():
    assert depth(package_graph()) <= MAX_DEPTH


#: How ``restitution cor`` starts (Python run in a child, ``ARGS`` the command's arguments): its own main, the
#: console script (pyproject.toml: ``restitution = "restitution.command:main"``) and ``python -m restitution``
#: (the script ``__main__.py`` runs as ``__main__``, as the console script's file does: neither is counted).
COR_STARTS = {
    "cor.main": "from restitution.cor import main\nmain(ARGS)",
    "console script": "from restitution.command import main\nmain(['cor', *ARGS])",
    "python -m restitution": ("import runpy\nsys.argv = ['restitution', 'cor', *ARGS]\ntry:\n"
                              "    runpy.run_module('restitution', run_name='__main__')\nexcept SystemExit as exc:\n"
                              "    assert not exc.code, exc.code"),
}


@pytest.mark.parametrize("start", sorted(COR_STARTS))
def test_cor_loads_nothing_of_sweep_scene_or_cosim_and_under_25_modules(start):
    """``restitution cor``, the simplest command, imports only the core, the tables and the readers
    (run in a child: a fresh interpreter's modules), and the dispatcher: it loaded 47 of the package's
    modules, 24 of them from sweep, scene and cosim, before the readers moved to the core, and 25 through
    the dispatcher before the result record and the option declarations stopped loading the physics and the
    readers."""
    import subprocess
    import sys

    code = ("import sys, io, contextlib\n"
            "ARGS = ['--sphere', 'chrome_steel', '--d', '6.35 mm', '--plate', 'al_6061', '--t', '3 mm', '--v', '2']\n"
            "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
            + "".join(f"    {line}\n" for line in COR_STARTS[start].splitlines())
            + "assert 'apparent COR' in out.getvalue(), out.getvalue()\n"
            "print(' '.join(m for m in sys.modules if m.split('.')[0] == 'restitution'))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    # restitution.fmu's own __init__ runs as the tables' parent (it loads its builders only when asked)
    assert not [m for m in loaded if package_layer(m)[0] in ("fmu", "cosim", "wing", "top")
                and package_layer(m)[1] != "cor" and m not in ("restitution.fmu", "restitution.command")], loaded
    assert len(loaded) < 25, loaded


def test_declaring_options_loads_no_reader():
    """``restitution materials`` and ``restitution fmu`` declare options (:mod:`restitution.options`) but read
    no impact's inputs: their start loads neither the readers (inputs) nor the interface table."""
    import subprocess
    import sys

    code = ("import sys\nimport restitution.options, restitution.materials_table\n"
            "print(' '.join(m for m in sys.modules if m.split('.')[0] == 'restitution'))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert "restitution.options" in loaded and not [m for m in loaded if m == "restitution.inputs"
                                                    or package_layer(m)[0] == "tables"], loaded


def test_the_version_module_loads_when_asked_and_stays_an_attribute():
    """``import restitution`` leaves :mod:`restitution.about` unloaded (``cor`` never shows the version),
    yet ``restitution.about`` and ``restitution.__version__`` answer as when it was imported at the top;
    an unknown name is still an AttributeError (run in a child: a fresh interpreter's modules)."""
    import subprocess
    import sys

    code = ("import sys, restitution\nloaded = 'restitution.about' in sys.modules\n"
            "about = restitution.about\nassert about.__name__ == 'restitution.about', about\n"
            "assert restitution.__version__ == about.VERSION\n"
            "try:\n    restitution.no_such_name\nexcept AttributeError:\n    print(loaded)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0 and result.stdout.split() == ["False"], result.stderr
