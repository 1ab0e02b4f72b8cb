"""What the project's pythonfmu slaves share: the start-up that decides which code an instance runs,
setters that refuse bad values and FMU states that carry a schema and are validated before they are
restored.

Shipped beside each slave script in the FMU's resources/ (a module name of its own: two pythonfmu
FMUs in one process share sys.modules). Nothing here may raise into pythonfmu, which would turn
any exception into fmi2Fatal: a refusal is logged with fmi2Error and changes nothing. (The start-up
raises only when the FMU's own files are unreadable: the instantiation then fails, as it must.)

In the built FMUs the C guard checks every value and keeps the FMU states itself, so these checks
are a second line: they hold for pythonfmu's own binaries (win64), which have no guard, and for
code that drives a slave directly.

Start-up: which code an instance runs
-------------------------------------
pythonfmu 0.7, at every fmi2Instantiate: puts the FMU's resources/ first on sys.path (and never takes
it off); imports the slave module by name, which only the first time in a process executes the
script (later it gets the cached module, whichever FMU's folder that came from); executes the script
again with the cached module's globals and a fresh dictionary as locals; and instantiates the class
the *cached module* holds. Each FMU ships its own copy of the package (resources/restitution), and a
host may delete an FMU's folder when it is done with it (fmpy's ``simulate_fmu`` does). Left to
plain imports, the next FMU found ``restitution`` in sys.modules with its folder gone and failed
with ``No module named 'restitution.fmu.models...'``; and an instance could run another FMU's (or the
host's) version of the physics without anyone knowing.

What the start-up does, at each execution of a slave script in an FMU (both executions above):

* the support module is the file this FMU ships, or the loaded one when it has the same SHA-256 (the
  slave checks before it calls anything here);
* :func:`start` (:func:`restitution_package`) picks the package the slave binds its names from. Rule: *an instance
  runs the code its FMU ships, or a copy verified to be the same*: the same SHA-256 for every file
  the FMU ships in resources/restitution (a version number would not do: a rebuilt checkout keeps
  it). In order:

  1. no ``restitution`` in the process: this FMU's copy, imported under that name;
  2. a ``restitution`` in the process that is the same code: that one (the host's installed
     package, compared file by file with what the FMU ships, or another FMU's copy, by the hashes
     recorded when it was loaded): one copy of the code in the process, and the host's and the FMU's
     results come from the same functions;
  3. otherwise this FMU's copy under a private name, ``_restitution_fmu_<digest>`` (its modules'
     relative imports stay inside it), shared by every FMU that ships the same files.

  Nothing is ever removed from or replaced in sys.modules under the name ``restitution``: the host
  may be using it (its ``cosim``, ``scene``, ... are not shipped), and so may a live instance of the
  other FMU: a co-simulation of both FMUs has two alive at once. A copy loaded from resources/ is
  imported whole, every module of it, so that it never needs its folder again: the folder may be
  deleted while the copy is still in use (by a live instance, by the cached slave class, or by the
  next FMU that ships the same files), and the package imports one module at call time
  (``zener_ode`` -> ``zener_exact``), which then comes from sys.modules;
* :func:`start`, at pythonfmu's second execution, makes pythonfmu instantiate a class that runs this
  FMU's code: when the cached module's class runs other code (another version of the FMU, or the
  slave of a checkout that differs from what the FMU ships), this FMU's script is loaded as a new
  module, which replaces the cached one in sys.modules, and its class is put where pythonfmu takes it.
  Nothing raises there: pythonfmu 0.7 does not check that execution and crashes the process (a
  segmentation fault) on an exception in it; a failure makes the instantiation fail with its message;
* sys.path loses the resources/ folders that no longer exist and the repeats pythonfmu adds
  (:func:`tidy_sys_path`).

The hashes cost about 1 ms per execution (some 25 small files). Not covered: two threads instantiating
pythonfmu FMUs at the same moment (the start-up reads and extends sys.modules without a lock), and an
FMU folder replaced in place by another version while the guard keeps an instance of the first
(fmi2Instantiate with the same resources/ path reuses it without running any Python).

Outside an FMU (a test or a build importing a slave from the package) the slave binds the importable
``restitution`` and nothing of the above is done.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import json
import os
import sys
import types

from pythonfmu.enums import Fmi2Status

#: Bumped when the layout of the state dictionary changes.
STATE_FORMAT = 1


def checked_setter(slave, variable, values: dict, on_change):
    """A setter for the input or parameter ``variable`` (a row of the model's interface table) that keeps
    ``values[variable.name]`` unless the new value is in its allowed range; a refused value is logged
    (name, value, allowed range) with fmi2Error. ``on_change(name)`` runs after an accepted change."""
    name, allowed = variable.name, variable.allowed_text()

    def set_value(value):
        try:
            good = variable.accepts(value)
        except (TypeError, ValueError, OverflowError):
            good = False
        if not good:
            slave.log(f"{name} = {value!r} is outside the allowed range: {allowed}", Fmi2Status.error)
            return
        if value != values[name]:
            values[name] = value
            on_change(name)
    return set_value


def state_check(variable):
    """The check a restored value of the input or parameter ``variable`` must pass: its allowed range,
    and for an Integer an int (a JSON state may carry anything)."""
    if variable.type == "Integer":
        return lambda value: isinstance(value, int) and not isinstance(value, bool) and variable.accepts(value)
    return lambda value: isinstance(value, (int, float)) and not isinstance(value, bool) and variable.accepts(value)


def state_schema(model: str, names) -> dict:
    """The tag a state of ``model`` carries: format, model identifier and its variables, in order."""
    return {"format": STATE_FORMAT, "model": model, "variables": list(names)}


def state_problem(state, schema: dict, checks: dict) -> str | None:
    """Why ``state`` cannot be restored into a slave with ``schema``, or None. ``checks`` maps each
    input and parameter to :func:`state_check`'s predicate; the other variables must be numbers."""
    if isinstance(state, dict) and "unreadable" in state:
        return f"the bytes are not a state ({state['unreadable']})"
    if not isinstance(state, dict) or set(state) != {"schema", "values"}:
        return "it is not a state of this FMU (expected the keys schema and values)"
    if state["schema"] != schema:
        got = state["schema"] if isinstance(state["schema"], dict) else {}
        if got.get("model") != schema["model"]:
            return f"it belongs to the model {got.get('model')!r}, not {schema['model']!r}"
        if got.get("format") != schema["format"]:
            return f"it was written in state format {got.get('format')!r}, this FMU reads {schema['format']}"
        return "its variable list differs from this FMU's"
    values = state["values"]
    if not isinstance(values, dict) or list(values) != schema["variables"]:
        return "its values do not match its variable list"
    for name, value in values.items():
        if not isinstance(value, (int, float)):
            return f"{name} = {value!r} is not a number"
        check = checks.get(name)
        try:
            good = check(value) if check is not None else True
        except (TypeError, ValueError, OverflowError):
            good = False
        if not good:
            return f"{name} = {value!r} is outside the allowed range"
    return None


def restore_state(slave, state, schema: dict, checks: dict, setters: dict) -> bool:
    """Restore a validated state through ``setters`` (name -> callable); otherwise log why with
    fmi2Error and change nothing. Returns whether it was restored."""
    problem = state_problem(state, schema, checks)
    if problem is not None:
        slave.log(f"fmi2SetFMUstate: the state is not restored: {problem}", Fmi2Status.error)
        return False
    for name, value in state["values"].items():
        setters[name](value)
    return True


def state_to_bytes(state) -> bytes:
    return json.dumps(state, allow_nan=True).encode("utf-8")


def state_from_bytes(data) -> dict:
    """The state in ``data``, or a dictionary that :func:`state_problem` rejects with the reason
    (never an exception: pythonfmu would make it fmi2Fatal)."""
    try:
        state = json.loads(bytes(data).decode("utf-8"))
    except (ValueError, TypeError, UnicodeDecodeError) as exc:
        return {"unreadable": f"{type(exc).__name__}: {exc}"}
    return state


# --- Start-up: which code an instance runs (the module docstring says what and why) -------------------

#: The package every FMU ships in its resources/.
PACKAGE = "restitution"
#: Set on a copy of the package loaded from an FMU's resources/: the hashes of the files it was loaded from.
SHIPPED_FILES = "__fmu_shipped_files__"
#: A slave module's globals: what code its class runs (see :func:`start`), its own slave class (see
#: :func:`settle`) and the package it bound its names from (the slaves' name for it).
SLAVE_CODE = "_SHIPPED_CODE"
SLAVE_CLASS = "_SLAVE_CLASS"
SLAVE_PACKAGE = "_restitution"


def _own_sha256() -> str | None:
    try:
        with open(__file__, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
    except OSError:
        return None


#: SHA-256 of this file, read when it was loaded. A slave in an FMU takes this module from sys.modules only
#: when it has the hash of the file its FMU ships beside it; otherwise it loads that file.
SOURCE_SHA256 = _own_sha256()


def _hash_files(paths: dict) -> dict | None:
    """key -> SHA-256 of the file ``paths[key]``; None when one of them cannot be read."""
    hashes = {}
    for key, path in paths.items():
        try:
            with open(path, "rb") as f:
                hashes[key] = hashlib.sha256(f.read()).hexdigest()
        except OSError:
            return None
    return hashes


def _package_files(resources: str) -> dict:
    """The files of the package the FMU ships, keyed by their path relative to ``resources`` with "/"
    ("restitution/model.py"), compiled caches left out."""
    root = os.path.join(resources, PACKAGE)
    if not os.path.isfile(os.path.join(root, "__init__.py")):
        raise ImportError(f"this FMU's resources folder {resources} has no {PACKAGE} package")
    files = {}
    for folder, dirs, names in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(names):
            if not name.endswith((".pyc", ".pyo")):
                path = os.path.join(folder, name)
                files[os.path.relpath(path, resources).replace(os.sep, "/")] = path
    return files


def shipped_code(resources: str | None, slave: str) -> dict | None:
    """Hashes of all the Python code the FMU in ``resources`` ships (None outside an FMU): its slave script
    (``slave``.py, key "slave"), this module ("support") and every file of its package (keys as
    :func:`_package_files`)."""
    if resources is None:
        return None
    paths = {"slave": os.path.join(resources, slave + ".py"), "support": os.path.join(resources, __name__ + ".py"),
             **_package_files(resources)}
    hashes = _hash_files(paths)
    if hashes is None:
        raise ImportError(f"cannot read the Python code this FMU ships in {resources}")
    return hashes


def _package_part(shipped: dict) -> dict:
    return {key: value for key, value in shipped.items() if key.startswith(PACKAGE + "/")}


def _digest(hashes: dict) -> str:
    return hashlib.sha256("".join(f"{key}\0{value}\0" for key, value in sorted(hashes.items())).encode()).hexdigest()


def _same_files(root: str, hashes: dict) -> bool:
    """Whether the files under ``root`` named by the keys of ``hashes`` have those hashes."""
    return _hash_files({key: os.path.join(root, *key.split("/")) for key in hashes}) == hashes


def _is_same_package(module, hashes: dict) -> bool:
    """Whether the loaded package ``module`` is the code whose files have ``hashes``: by the hashes
    recorded when it was loaded from an FMU, else by its files (the host's package: every file the FMU
    ships must be there, the same)."""
    recorded = getattr(module, SHIPPED_FILES, None)
    if recorded is not None:
        return recorded == hashes
    init = getattr(module, "__file__", None)
    if not init or os.path.basename(init) != "__init__.py":
        return False
    return _same_files(os.path.dirname(os.path.dirname(os.path.abspath(init))), hashes)


def is_shipped_package(package, resources: str) -> bool:
    """Whether the loaded package ``package`` is the code the FMU in ``resources`` ships: a copy loaded
    from it (rules 1 and 3 of the module docstring), or a package with the same files (rule 2)."""
    hashes = _hash_files(_package_files(resources))
    return hashes is not None and _is_same_package(package, hashes)


def _module_names(root: str) -> list:
    """The dotted names, relative to the package in ``root``, of every module and subpackage in it."""
    names = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs
                         if d != "__pycache__" and os.path.isfile(os.path.join(folder, d, "__init__.py")))
        relative = os.path.relpath(folder, root)
        prefix = "" if relative == os.curdir else relative.replace(os.sep, ".") + "."
        if prefix:
            names.append(prefix[:-1])
        names += [prefix + f[:-3] for f in sorted(files) if f.endswith(".py") and f != "__init__.py"]
    return names


def _load_copy(resources: str, name: str, hashes: dict):
    """The package in ``resources`` imported as ``name`` with every module in it (so that it never needs
    its folder again), marked with ``hashes``. On failure nothing of it stays in sys.modules."""
    root = os.path.join(resources, PACKAGE)
    importlib.invalidate_caches()  # a folder deleted and extracted again at the same path: no stale listings
    try:
        spec = importlib.util.spec_from_file_location(name, os.path.join(root, "__init__.py"),
                                                      submodule_search_locations=[root])
        package = importlib.util.module_from_spec(spec)
        sys.modules[name] = package
        spec.loader.exec_module(package)
        for sub in _module_names(root):
            importlib.import_module(f"{name}.{sub}")
    except BaseException:
        for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
            del sys.modules[key]
        raise
    setattr(package, SHIPPED_FILES, hashes)
    return package


def tidy_sys_path(resources: str) -> None:
    """Take off sys.path the FMU resources/ folders (pythonfmu's entries: a folder named "resources") that
    no longer exist, and the repeats of one (pythonfmu adds its folder at every instantiation), with their
    cached finders. ``resources``, this FMU's folder, first on sys.path, stays first."""
    kept, seen, dropped = [], set(), []
    for entry in sys.path:
        ours = isinstance(entry, str) and (entry == resources
                                           or os.path.basename(os.path.normpath(entry)) == "resources")
        if ours and (entry in seen or not os.path.isdir(entry)):
            dropped.append(entry)
            continue
        if ours:
            seen.add(entry)
        kept.append(entry)
    if dropped:
        sys.path[:] = kept
        for entry in set(dropped) - seen:
            sys.path_importer_cache.pop(entry, None)


def restitution_package(resources: str, code: dict):
    """The ``restitution`` package the slave in ``resources`` runs (rules 1-3 of the module docstring),
    ``code`` being :func:`shipped_code`."""
    tidy_sys_path(resources)
    shipped = _package_part(code)
    loaded = sys.modules.get(PACKAGE)
    if loaded is None:  # 1: the process has none: this FMU's, under its name
        return _load_copy(resources, PACKAGE, shipped)
    if _is_same_package(loaded, shipped):  # 2: the one in the process is the same code
        return loaded
    private = f"_{PACKAGE}_fmu_{_digest(shipped)[:16]}"  # 3: this FMU's, under a name of its own
    copy = sys.modules.get(private)
    if copy is not None and getattr(copy, SHIPPED_FILES, None) == shipped:
        return copy
    return _load_copy(resources, private, shipped)


def submodule(package, name: str):
    """``package``'s submodule ``name`` ("model", "fmu.models.bouncing_ball.variables"): through the
    package's attributes when it is loaded (a copy from an FMU always is, whole), else imported."""
    module = package
    for part in name.split("."):
        module = getattr(module, part, None)
        if not isinstance(module, types.ModuleType):
            return importlib.import_module(f"{package.__name__}.{name}")
    return module


def _runs(record, shipped: dict) -> bool:
    """Whether a slave module whose :data:`SLAVE_CODE` is ``record`` runs the code whose hashes are
    ``shipped`` (:func:`shipped_code`). A record it cannot read (another version of this module wrote
    it, or none did) is not the same code."""
    try:
        if "hashes" in record:  # a slave from an FMU: the hashes of what that FMU shipped
            return record["hashes"] == shipped
        # a slave from the package (a checkout, an installation): its script and this module as they were
        # read, and the package it bound
        return (record["slave"] == shipped["slave"] and record["support"] == shipped["support"]
                and _is_same_package(record["package"], _package_part(shipped)))
    except Exception:  # noqa: BLE001 - anything unreadable is a difference
        return False


#: What pythonfmu was handed in place of a slave class because the start-up failed (see :func:`start`):
#: kept, since pythonfmu 0.7 drops a reference it does not own when the call it makes fails.
_REFUSALS = []


def _refusal(message: str):
    """A callable that pythonfmu calls as the slave class, and that raises ImportError(``message``):
    the instantiation fails with that message (fmi2Instantiate returns NULL)."""
    def refuse(**_kwargs):
        raise ImportError(message)
    _REFUSALS.append(refuse)
    return refuse


def _fresh_module(resources: str, name: str):
    """The slave script ``name``.py in ``resources`` executed as a new module, which replaces the one in
    sys.modules (restored if the script fails)."""
    spec = importlib.util.spec_from_file_location(name, os.path.join(resources, name + ".py"))
    fresh = importlib.util.module_from_spec(spec)
    previous = sys.modules.get(name)
    sys.modules[name] = fresh
    try:
        spec.loader.exec_module(fresh)
    except BaseException:
        if previous is not None:
            sys.modules[name] = previous
        else:
            sys.modules.pop(name, None)
        raise
    return fresh


def start(module_globals: dict, module_locals: dict, class_name: str, resources: str | None):
    """The package a slave script binds its names from, called before anything of it is used
    (``globals()``, ``locals()`` of the script's top level, its slave class's name, its FMU's resources/
    folder or None outside an FMU).

    At an import: the package (:func:`restitution_package` in an FMU, else the importable one), and the
    module records what code its class runs (:data:`SLAVE_CODE`: in an FMU the hashes of every file the
    FMU ships; outside, the hashes of the script and of this module, and the package). An error here
    fails the import, and pythonfmu reports it.

    At pythonfmu's second execution of an fmi2Instantiate (globals: the cached module's, whose class
    pythonfmu instantiates next): when that class runs the code this FMU ships, it stays; otherwise this
    FMU's script is loaded as a new module, which replaces the cached one in sys.modules, and its class
    is put where pythonfmu takes it (``class_name`` in the cached module; instances alive keep their
    class). Nothing may raise here: pythonfmu 0.7 does not check this execution and crashes the process
    on its error; a failure instead puts there a callable that raises it, and the instantiation fails
    with its message. Returns the package the cached or new module bound (the names this execution binds
    are thrown away)."""
    if module_globals is module_locals:
        if resources is None:
            package = importlib.import_module(PACKAGE)
            script = _hash_files({"slave": module_globals["__file__"]}) or {"slave": None}
            module_globals[SLAVE_CODE] = {"slave": script["slave"], "support": SOURCE_SHA256, "package": package}
            return package
        code = shipped_code(resources, module_globals["__name__"])
        package = restitution_package(resources, code)
        module_globals[SLAVE_CODE] = {"hashes": code}
        return package
    cached = module_globals.get(SLAVE_PACKAGE)
    try:
        if resources is None:
            return cached if cached is not None else importlib.import_module(PACKAGE)
        tidy_sys_path(resources)
        if _runs(module_globals.get(SLAVE_CODE), shipped_code(resources, module_globals["__name__"])):
            own = module_globals.get(SLAVE_CLASS)
            if own is not None:  # an earlier execution may have put another class there
                module_globals[class_name] = own
            return cached
        fresh = _fresh_module(resources, module_globals["__name__"])
        module_globals[class_name] = getattr(fresh, class_name)
        return getattr(fresh, SLAVE_PACKAGE)
    except Exception as exc:  # noqa: BLE001 - see above: reported by the instantiation instead
        module_globals[class_name] = _refusal(
            f"{class_name}: this FMU's Python code could not be started in this process "
            f"({type(exc).__name__}: {exc})")
        return cached if cached is not None else sys.modules.get(PACKAGE)


def settle(module_globals: dict, module_locals: dict, class_name: str) -> None:
    """The last statement of a slave script: at an import, remembers the module's own class
    (:data:`SLAVE_CLASS`), which :func:`start` puts back where pythonfmu takes it."""
    if module_globals is module_locals:
        module_globals[SLAVE_CLASS] = module_globals[class_name]
