"""The two ways a sweep evaluates its cases: the vectorized package and the FMU itself.

Both take the case columns of :meth:`SweepSpec.cases` and return the FMU's outputs by name
(plus ``ok``: inputs in range and the evaluation succeeded). Invalid inputs give NaN reals
and false flags in both, as the FMU reads them.

:class:`FmuBackend` runs ``SpherePlateImpact.fmu`` (FMI 2.0 or FMI 3.0) through fmpy, by a
:class:`restitution.cosim.FmuInstance`: one instance per worker process (per thread, where a
worker runs several), loaded on first use and reused across chunks with a reset, as fmpy's
parameter-variation example does.
The FMU file travels with the sweep (as bytes, once per worker), so workers on other
machines need no shared file system.

A pythonfmu FMU runs in the host's interpreter. Its start-up picks the code it runs: the
``restitution`` package it ships, or the host's when every file it ships is the same there (one
copy of the code in the process); an FMU built from other sources runs its own copy under a
private name. The back end checks that the package the FMU evaluates is the code it ships and
reports that code's fingerprint with the results. It never takes the host's modules out of
sys.modules: a Dask worker's other threads import them while an instance is created.
"""
from __future__ import annotations

import atexit
import hashlib
import inspect
import os
import shutil
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

from ..fmu.models.sphere_plate_impact.variables import TABLE
from ..model import PARAMETERS
from .spec import CODES, INPUTS, INTEGER_INPUTS, OUTPUTS, SETTABLE, is_one_value_view

__all__ = ["Backend", "PackageBackend", "FmuBackend", "get_backend", "code_fingerprint", "release_fmus"]

_REAL_OUT = [name for name, _f, t in OUTPUTS if t == "Real"]
_BOOL_OUT = [name for name, _f, t in OUTPUTS if t == "Boolean"]
#: impact()'s keyword options (the inputs that are neither v nor a material or geometry parameter), each
#: one value per vectorized call; the edge distance is an array like the geometry (it may be drawn at random)
_OPTION_NAMES = tuple(v.name for v in SETTABLE
                      if v.key not in {"v", "plate_edge_distance", *(key for key, _unit, _check in PARAMETERS)})


def code_fingerprint(package_dir=None) -> str:
    """sha256 (first 12 hex digits) of a ``restitution`` package's physics: its top-level
    ``.py`` files and ``data/``. Default: the package this process imported."""
    if package_dir is None:
        package_dir = Path(__file__).resolve().parent.parent
    package_dir = Path(package_dir)
    h = hashlib.sha256()
    files = sorted(package_dir.glob("*.py")) + sorted((package_dir / "data").glob("*"))
    for f in files:
        if f.is_file():
            h.update(f.relative_to(package_dir).as_posix().encode())
            h.update(f.read_bytes())
    return h.hexdigest()[:12]


_FINGERPRINT = None


def _own_fingerprint() -> str:
    global _FINGERPRINT
    if _FINGERPRINT is None:
        _FINGERPRINT = code_fingerprint()
    return _FINGERPRINT


def _column(values, n: int, vtype: str) -> np.ndarray:
    """An output of one vectorized call as a table column of ``n`` cases (no copy where it already is one)."""
    column = np.asarray(values, dtype=bool if vtype == "Boolean" else float)
    return column if column.shape == (n,) else np.array(np.broadcast_to(column, (n,)))


def _empty_outputs(n: int) -> dict:
    out = {name: np.full(n, np.nan) for name in _REAL_OUT}
    out.update({name: np.zeros(n, dtype=bool) for name in _BOOL_OUT})
    out["ok"] = np.zeros(n, dtype=bool)
    return out


def inputs_ok(cases: dict) -> np.ndarray:
    """Cases whose inputs the FMU accepts (each in its declared range, codes whole numbers): the
    others read NaN."""
    ok = np.ones(np.size(cases["v_approach"]), dtype=bool)
    every_constant_ok = True  # the one-value columns, checked once each and applied to ok once
    with np.errstate(invalid="ignore"):
        for var in SETTABLE:
            x = np.asarray(cases[var.name], dtype=float)
            constant = x.ndim == 0 or is_one_value_view(x)
            if constant:  # one value for every case
                x = x.reshape(-1)[:1]
            low, high, low_open, high_open = var.interval
            good = (x > low) if low_open else (x >= low)
            good &= (x < high) if high_open else (x <= high)
            if var.type == "Integer":
                good &= x == np.round(x)
            if constant:
                every_constant_ok = every_constant_ok and bool(good[0])
            else:
                ok &= good
    if not every_constant_ok:
        ok[:] = False
    return ok


class Backend:
    """How a chunk of cases is evaluated. Subclasses are small and picklable."""

    name = "backend"
    #: Cases per Dask task when the caller does not choose (about a second of work).
    default_chunk = 10_000
    #: Cases per chunk of a serial sweep whose table stays in memory only (no parts on disk); None:
    #: :attr:`default_chunk`.
    in_memory_chunk = None

    def payload(self):
        """What each task needs besides the cases (sent to the workers once)."""
        return None

    def evaluate(self, cases: dict, payload=None, outputs=None) -> tuple[dict, dict]:
        """(output columns, info) for the case columns; ``outputs``: the output names needed
        (None: all), which a back end may use to skip work."""
        raise NotImplementedError

    def describe(self) -> str:
        return self.name


class PackageBackend(Backend):
    """:func:`restitution.impact` on whole arrays: the fast path."""

    name = "package"
    default_chunk = 100_000
    #: a serial sweep kept in memory only: up to 10^6 cases are one chunk, whose arrays become the table
    #: without a copy (TableBuilder); impact()'s temporaries for them peak near the table's own size
    in_memory_chunk = 1_000_000

    def evaluate(self, cases: dict, payload=None, outputs=None):
        from ..model import impact, published

        n = np.size(cases["v_approach"])
        columns, fields, publish = _kept_outputs(outputs)
        out = None
        for sel, inputs, options in impact_groups(cases, np.flatnonzero(inputs_ok(cases))):
            values = impact(**inputs, **options, validate=False, outputs=fields)  # the kept columns' work only
            values = values.as_dict() if fields is None else values
            values = published(values) if publish else values
            if out is None and np.size(sel) == n:  # the usual chunk, every case in one call: its arrays are the columns
                out = {name: _column(values[field_name], n, vtype) for name, field_name, vtype in columns}
                out["ok"] = np.ones(n, dtype=bool)
                continue
            out = _empty_outputs(n) if out is None else out
            for name, field_name, _t in columns:
                out[name][sel] = values[field_name]
            out["ok"][sel] = True
        return (_empty_outputs(n) if out is None else out), {"code": _own_fingerprint(), "pid": os.getpid()}


def _kept_outputs(keep):
    """(the rows of OUTPUTS a sweep keeping the columns ``keep`` (None: all) writes, impact()'s ``outputs=``
    for them (None: all), whether :func:`~restitution.model.published` changes any of them); where it does,
    the outputs it reads too (``contact_ends``, ``edge_echo``)."""
    from ..model import ENDLESS

    if keep is None:
        return OUTPUTS, None, True
    columns = tuple(row for row in OUTPUTS if row[0] in keep)
    fields = [field for _name, field, _t in columns]
    publish = not {*ENDLESS, "edge_echo"}.isdisjoint(fields)
    if publish:
        fields += [field for field in ("contact_ends", "edge_echo") if field not in fields]
    return columns, tuple(fields), publish


def _impact_input(column, sel) -> np.ndarray | float:
    """One input of impact() for the cases ``sel`` (None: all) of a case column: a float where the column
    is a view of one value (SweepSpec.cases gives a sweep's fixed inputs so), which lets impact() compute
    the terms that depend only on the parameters once for the chunk instead of once per case; else the
    column's values as float64."""
    column = np.asarray(column, dtype=float)
    if is_one_value_view(column):
        return float(column[0])
    return column if sel is None else column[sel]


def impact_groups(cases: dict, rows):
    """(rows, impact() input arrays, impact() option keywords) for the ``rows`` of ``cases``,
    grouped by their integer-coded options (one vectorized call per group)."""
    rows = np.asarray(rows)
    if rows.size == 0:
        return
    every_case = rows.size == np.size(cases["v_approach"])  # rows is then 0..n-1: no copies needed
    columns = [np.asarray(cases[k], dtype=float) if every_case else np.asarray(cases[k], dtype=float)[rows]
               for k in _OPTION_NAMES]
    if all(is_one_value_view(col) or (col == col[0]).all() for col in columns):
        # the usual chunk: one choice of options, found without stacking the columns (np.unique sorts
        # the cases: 60 % of a sweep)
        groups, inverse = np.array([[col[0] for col in columns]]), None
    else:
        groups, inverse = np.unique(np.stack(columns, axis=1), axis=0, return_inverse=True)
    for g, opt in enumerate(groups):
        sel = rows if inverse is None else rows[inverse.ravel() == g]
        whole = inverse is None and every_case
        inputs = {kw: _impact_input(cases[name], None if whole else sel)
                  for name, kw, _t, _s in INPUTS if name not in _OPTION_NAMES}
        yield sel, inputs, {TABLE.key_of(name): (TABLE[name].word(int(x)) if name in CODES else float(x))
                            for name, x in zip(_OPTION_NAMES, opt)}


# --- the FMU back end --------------------------------------------------------------------
_LOCK = threading.Lock()
_EXTRACTED: dict = {}  # sha -> (unzip dir, created-by-us dir or None)
_INSTANCES: dict = {}  # (sha, thread id) -> _LoadedFmu


class _LoadedFmu:
    """One instance of the FMU (a :class:`restitution.cosim.FmuInstance`) with its value references,
    created with the FMU's own bundled code and a logger that drops messages (a bad case shows as NaN
    outputs and ok = False)."""

    def __init__(self, unzip_dir: str):
        from ..cosim.fmu import FmuInstance  # the FMU back end's (the package's sweeps do without cosim)
        self.unzip_dir = unzip_dir
        self.instance = FmuInstance(unzip_dir, instance_name=f"sweep-{os.getpid()}-{threading.get_ident()}",
                                    unzip_dir=unzip_dir, instantiate=self._instantiate)
        self.slave = self.instance.slave  # None once closed
        variables = self.instance.variables
        missing = [name for name, _kw, _t, _s in INPUTS if name not in variables]
        missing += [name for name, _f, _t in OUTPUTS if name not in variables]
        if missing:
            self.close()
            raise ValueError(f"{unzip_dir}: not a SpherePlateImpact FMU (no variable(s) {missing})")
        self.busy = False  #: a chunk is being evaluated (in the thread that owns the instance)
        self.doomed = None  #: released while busy: closed (and this directory removed) when the chunk returns

    def _instantiate(self, slave):
        if os.path.isfile(os.path.join(self.unzip_dir, "resources", "slavemodule.txt")):  # a pythonfmu FMU
            self.code_file = _instantiate_python_fmu(slave, self.unzip_dir)
            self.code = code_fingerprint(Path(self.code_file).parent)
        else:  # a native FMU (C only): its binary is the code that runs
            from ..cosim.fmu import quiet_instantiate
            quiet_instantiate(slave)
            self.code_file = slave.dll._name
            self.code = hashlib.sha256(Path(self.code_file).read_bytes()).hexdigest()[:12]

    def reset(self):
        self.instance.reset()

    def evaluate(self, cases: dict, outputs=None) -> dict:
        """Set every input of every case (the varying ones case by case), read the outputs
        (``outputs``: names to read, default all; ``e`` is always read, for ``ok``)."""
        with _LOCK:
            if self.slave is None or self.doomed is not None:
                raise RuntimeError("this FMU instance was released")
            self.busy = True
        try:
            return self._evaluate(cases, outputs)
        finally:
            with _LOCK:
                self.busy = False
                doomed, self.doomed = self.doomed, None
            if doomed is not None:  # release_fmus ran meanwhile (a cancelled chunk): free it now
                self.close()
                if doomed:
                    shutil.rmtree(doomed, ignore_errors=True)

    def _evaluate(self, cases: dict, outputs=None) -> dict:
        from ..cosim.fmu import FmiStatusError
        n = np.size(cases["v_approach"])
        self.reset()
        reals = [name for name, _kw, t, _s in INPUTS if t == "Real"]
        columns = {name: np.asarray(cases[name], dtype=float) for name, _kw, _t, _s in INPUTS}
        for name in INTEGER_INPUTS:  # an FMI 2.0 Integer is 32 bits: a code beyond would wrap, not fail
            bad = columns[name][~np.isin(columns[name], list(CODES[name].values()))]
            if bad.size:
                raise ValueError(f"{name} = {float(bad[0])!r} is out of range: codes {sorted(CODES[name].values())}")
        varying = {name for name, col in columns.items() if n and not np.all(col == col[0])}
        fmu = self.instance
        real_names = [k for k in _REAL_OUT if outputs is None or k in outputs or k == "e"]
        bool_names = [k for k in _BOOL_OUT if outputs is None or k in outputs]
        if n:
            # The constant columns once; the varying ones case by case.
            try:
                fmu.writer(*(k for k in reals if k not in varying))(
                    [float(columns[k][0]) for k in reals if k not in varying])
                fmu.writer(*(k for k in INTEGER_INPUTS if k not in varying))(
                    [int(columns[k][0]) for k in INTEGER_INPUTS if k not in varying])
            except FmiStatusError:  # a value every case shares is refused: no case can be evaluated
                out = _empty_outputs(n)
                return {k: v for k, v in out.items() if k in real_names or k in bool_names or k == "ok"}
        var_real = [k for k in reals if k in varying]
        var_int = [k for k in INTEGER_INPUTS if k in varying]
        real_rows = np.stack([columns[k] for k in var_real], axis=1).tolist() if var_real else None
        int_rows = np.stack([columns[k] for k in var_int], axis=1).astype(int).tolist() if var_int else None
        real_out = np.empty((n, len(real_names)))
        bool_out = np.empty((n, len(bool_names)), dtype=bool)
        get_real, get_bool = fmu.reader(*real_names), fmu.reader(*bool_names)
        set_real, set_int = fmu.writer(*var_real), fmu.writer(*var_int)
        check = _INTERRUPT_CHECK  # serial runs: Ctrl-C taken between FMU calls, not at the chunk's end
        for i in range(n):
            if check is not None:
                check()
            if self.doomed is not None:  # released meanwhile: the chunk was cancelled, stop between calls
                raise RuntimeError("the sweep was cancelled: FMU instance released")
            try:
                if real_rows is not None:
                    set_real(real_rows[i])
                if int_rows is not None:
                    set_int(int_rows[i])
            except FmiStatusError:
                # The FMU refused a value of this case (Error, logged): the case is out of range,
                # as an FMU that keeps the value and reads NaN reports it. The next case sets every
                # varying input again.
                real_out[i] = np.nan
                bool_out[i] = False
                continue
            real_out[i] = get_real()
            if bool_names:
                bool_out[i] = get_bool()
        out = {name: real_out[:, j] for j, name in enumerate(real_names)}
        out.update({name: bool_out[:, j] for j, name in enumerate(bool_names)})
        out["ok"] = ~np.isnan(out["e"])
        return out

    def close(self):
        if self.slave is not None:
            try:
                self.instance.close()
            except Exception:  # noqa: BLE001 - best effort at shutdown
                pass
            self.slave = None


def _instantiate_python_fmu(slave, unzip_dir: str) -> str:
    """Instantiate a pythonfmu FMU (FMI 2.0); the file of the ``impact`` the FMU runs, checked to be the
    code the FMU ships: its own copy, or the host's ``restitution`` when every file the FMU ships is the
    same (the FMU's start-up decides, as in any Python host). Nothing is taken out of sys.modules: other
    threads of this process (a Dask worker's) import ``restitution`` modules meanwhile."""
    from ..cosim.fmu import quiet_instantiate
    from ..fmu.models.restitution_slave_support import SLAVE_PACKAGE, is_shipped_package

    resources = os.path.join(unzip_dir, "resources")
    slave_module = Path(resources, "slavemodule.txt").read_text().strip()
    with _LOCK:  # the FMU's start-up reads and extends sys.modules unguarded: one instantiation at a time
        path_before = list(sys.path)
        try:
            quiet_instantiate(slave)
        finally:
            sys.path[:] = path_before  # pythonfmu prepends resources/; the FMU's modules are loaded
        fmu_module = sys.modules.get(slave_module)
    impact_fn = getattr(fmu_module, "impact_record_at", None)  # what the slave evaluates at each step
    impact_fn = inspect.unwrap(impact_fn) if impact_fn is not None else None  # past the unit layer
    code_file = getattr(getattr(impact_fn, "__code__", None), "co_filename", None)
    package = getattr(fmu_module, SLAVE_PACKAGE, None)
    if code_file is None or package is None or not is_shipped_package(package, resources):
        raise RuntimeError(f"the FMU in {unzip_dir} does not run the restitution package it ships "
                           f"(impact_record_at() comes from {code_file})")
    return code_file


def _fmu_dir(payload) -> str:
    """Unzip directory of the FMU given as (sha, bytes) or (sha, path), extracted once per process."""
    sha, data = payload
    with _LOCK:
        if sha in _EXTRACTED:
            return _EXTRACTED[sha][0]
    from fmpy import extract

    base = None
    try:
        from distributed import get_worker
        base = get_worker().local_directory
    except Exception:  # noqa: BLE001 - not in a Dask worker
        pass
    own = tempfile.mkdtemp(prefix=f"restitution-sweep-{sha[:8]}-", dir=base)
    if isinstance(data, (bytes, bytearray)):
        fmu_file = os.path.join(own, "model.fmu")
        with open(fmu_file, "wb") as f:
            f.write(data)
    else:
        fmu_file = str(data)
    unzip = extract(fmu_file, unzipdir=os.path.join(own, "unzipped"))
    with _LOCK:
        _EXTRACTED.setdefault(sha, (unzip, own))
        return _EXTRACTED[sha][0]


def _instance(payload) -> _LoadedFmu:
    key = (payload[0], threading.get_ident())
    with _LOCK:
        loaded = _INSTANCES.get(key)
    if loaded is None:
        loaded = _LoadedFmu(_fmu_dir(payload))
        with _LOCK:
            _INSTANCES[key] = loaded
    return loaded


def release_fmus() -> int:
    """Free every FMU instance this process holds and delete their extracted files; the count freed.

    An instance evaluating a chunk in another thread (a task that was cancelled but still runs:
    Dask cannot stop a running task) is freed by that thread when the chunk returns, never under it."""
    with _LOCK:
        instances = list(_INSTANCES.values())
        _INSTANCES.clear()
        extracted = list(_EXTRACTED.values())
        _EXTRACTED.clear()
        busy = [inst for inst in instances if inst.busy]
        idle = [inst for inst in instances if not inst.busy]
        for inst in instances:  # from now on evaluate() refuses them
            inst.doomed = ""
        dirs = []
        for unzip, own in extracted:
            user = next((inst for inst in busy if inst.unzip_dir == unzip), None)
            if user is None:
                dirs.append(own)
            else:  # removed when that chunk returns
                user.doomed = own
    for inst in idle:
        inst.close()
    for own in dirs:
        shutil.rmtree(own, ignore_errors=True)
    return len(instances)


#: Set by a serial sweep (restitution.sweep.run) to its DeferredInterrupt's check: the FMU back end
#: calls it between cases, so Ctrl-C ends the chunk between two FMU calls without waiting for it.
_INTERRUPT_CHECK = None


atexit.register(release_fmus)


class FmuBackend(Backend):
    """``SpherePlateImpact.fmu`` through fmpy, one reused instance per worker process.

    ``fmu``: path of the FMU (default: dist/SpherePlateImpact.fmu, built if missing).
    """

    name = "fmu"
    default_chunk = 2_000

    def __init__(self, fmu=None):
        if fmu is None:
            from ..fmu.builders.products import default_fmu
            fmu = default_fmu()
        self.path = Path(fmu).resolve()
        data = self.path.read_bytes()
        self.sha = hashlib.sha256(data).hexdigest()

    def payload(self):
        return (self.sha, self.path.read_bytes())

    def local_payload(self):
        """Payload for an in-process run: the path instead of the bytes."""
        return (self.sha, str(self.path))

    def evaluate(self, cases: dict, payload=None, outputs=None):
        if payload is None:
            payload = self.local_payload()
        fmu = _instance(payload)
        out = fmu.evaluate(cases, outputs)
        return out, {"code": fmu.code, "pid": os.getpid(), "fmu_code_file": fmu.code_file}

    def describe(self) -> str:
        return f"fmu ({self.path.name}, sha256 {self.sha[:12]})"


def get_backend(name: str = "package", fmu=None) -> Backend:
    """A back end by name: 'package' (vectorized) or 'fmu' (``fmu``: path of the FMU)."""
    if isinstance(name, Backend):
        return name
    if name in ("package", "vector", "vectorized", "numpy"):
        return PackageBackend()
    if name == "fmu":
        return FmuBackend(fmu)
    raise ValueError(f"back end {name!r}: use 'package' or 'fmu'")
