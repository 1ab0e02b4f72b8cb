"""Run a sweep on Dask (a local cluster, or an existing scheduler) or serially, and keep the table.

    from restitution.sweep import SweepSpec, run_sweep
    spec = SweepSpec(pairs=["s2_tool_steel/al_6061"], grid={"v_approach": {"geomspace": [0.1, 10, 50]},
                                                              "t_over_d": {"geomspace": [0.1, 10, 40]}})
    result = run_sweep(spec)                             # LocalCluster sized to this machine
    result = run_sweep(spec, scheduler="tcp://10.0.0.5:8786", backend="fmu")   # an existing cluster
    result.write("map.parquet"); result.plot("map.png")

The work is cut into chunks of consecutive case indices; each Dask task builds its cases
from the spec (nothing large travels to the workers) and evaluates them with the back end; a
finished chunk comes back as one buffer (:class:`~restitution.sweep.table.PackedColumns`) and the
table is joined from the chunks once they are all in.

With ``parts=DIR`` every finished chunk is written to DIR as it completes (one Parquet file a
chunk, its one row group encoded once, written under a temporary name and renamed, its footer
recording its case range and the CRC-32 of its column chunks, :mod:`restitution.sweep.parts`), beside
a ``manifest.json`` naming the spec, back end, chunk size and columns; the result's
:meth:`~SweepResult.write` then joins the parts' column chunks into the Parquet table without encoding
anything again. An I/O error writing one raises
:class:`~restitution.output_files.OutputWriteError` and keeps the chunks already written. An interrupt (Ctrl-C) then
raises :class:`SweepInterrupted` carrying the table of the finished chunks, and
``resume=True`` on the same DIR checks every part and evaluates only the chunks that are missing
or damaged (a damaged part is removed, one line on stderr). With
``in_memory=False`` as well, nothing but counts stays in memory: the result's :meth:`~SweepResult.write`
streams the table from DIR chunk by chunk (for tables bigger than the memory budget, see
:func:`restitution.sweep.size.plan_size`).
"""
from __future__ import annotations

import contextlib
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from ..cosim.interrupt import DeferredInterrupt
from .backends import Backend, FmuBackend, code_fingerprint, get_backend, release_fmus
from .cluster import CASE_SECONDS, cost_class, count_workers, describe_client, open_client
from .parts import PartStore
from .result import DiskSweepResult, SweepResult
from .size import check_case_numbers
from .spec import SweepSpec
from .table import PackedColumns, TableBuilder, keep_columns, table_counts

__all__ = ["run_sweep", "SweepInterrupted"]


class SweepInterrupted(KeyboardInterrupt):
    """An interrupted sweep: ``result`` holds the finished chunks, ``missing`` counts the cases left."""

    def __init__(self, result: "SweepResult", missing: int):
        super().__init__(f"sweep interrupted: {missing} of {missing + len(result)} cases missing")
        self.result = result
        self.missing = missing


#: Chunks submitted per worker at a time in a Dask run: one computing, one waiting, so a worker never
#: idles while this process takes a result, and memory does not grow with the sweep.
IN_FLIGHT_PER_WORKER = 2


def _run_chunk(start: int, stop: int, spec: SweepSpec, backend: Backend, payload=None, keep=None,
               packed: bool = False):
    cpu = time.thread_time()
    cases = spec.cases(start, stop)
    outputs, info = backend.evaluate(cases, payload, keep)
    info["cpu"] = time.thread_time() - cpu
    cases.update(outputs)
    if keep is not None:
        cases = {k: v for k, v in cases.items() if k in keep}
    info["counts"] = table_counts(cases)
    return (PackedColumns(cases) if packed else cases), info


def _chunks(n: int, chunk_size: int):
    return [(s, min(s + chunk_size, n)) for s in range(0, n, chunk_size)]


#: A serial sweep kept in memory evaluates chunks of at most about this much work [s] (CASE_SECONDS for
#: its options), for the progress bar's sake: 10^6 cases of the package's default options are 0.3 s,
#: but with zener_method = ode they would be an hour and a half.
IN_MEMORY_SECONDS = 5.0


def _in_memory_chunk(spec, backend) -> int:
    """Cases per chunk of a serial sweep kept in memory: the back end's ``in_memory_chunk``, or fewer
    where that is more than :data:`IN_MEMORY_SECONDS` of work."""
    seconds = CASE_SECONDS.get(backend.name, (0.0,) * 3)[cost_class(spec)]
    return max(1, min(backend.in_memory_chunk, round(IN_MEMORY_SECONDS / seconds))) if seconds > 0 \
        else backend.in_memory_chunk


def run_sweep(spec: SweepSpec | dict, backend: str | Backend = "package", *, fmu=None, scheduler=None,
              n_workers: int | None = None, chunk_size: int | None = None, progress: bool = False,
              columns=None, release: bool = True, parts=None, resume: bool = False,
              in_memory: bool = True, on_chunk=None) -> SweepResult:
    """Evaluate every case of ``spec`` and return the table.

    ``backend``: "package" (vectorized :func:`restitution.impact`) or "fmu" (the FMU at ``fmu``,
    default dist/SpherePlateImpact.fmu). ``scheduler``: None (Dask's configured scheduler
    address, else a LocalCluster of ``n_workers`` processes, default one per core),
    "local" (always a new LocalCluster), a scheduler address, a ``distributed.Client``, or
    "serial" (no Dask: one loop in this process, for reference and debugging).
    ``chunk_size``: cases per task (default: the back end's, at most a quarter of each worker's
    share so the work spreads and progress moves; a serial package sweep kept in memory only takes up
    to 10^6 cases at a time, and a table of one chunk is that chunk's arrays, not a copy).
    ``progress``: a progress line on stderr (redrawn in a terminal; elsewhere only the final state). ``columns``: keep only these
    columns (besides ``case``, ``pair``, ``ok`` and the validity flags, which every table has), for
    sweeps whose full table would be too big to gather. ``release=False`` keeps the FMU instances
    loaded in the workers for the next sweep (free them with ``client.run(release_fmus)``).
    ``parts``: directory where each finished chunk is written as it completes; ``resume=True``
    keeps the chunks already there (same spec, back end, chunk size and columns) and evaluates
    only the missing ones. ``in_memory=False`` (needs ``parts``): the chunks are not gathered, a
    :class:`DiskSweepResult` streams the table from ``parts`` when written. ``on_chunk(start, stop,
    columns)`` is called in this process with each chunk's columns (cases ``start ... stop - 1``) as it
    is finished, and with ``resume`` each one kept from ``parts`` as the part store checks it (no second
    read), in no particular order, so that an analysis keeps the few columns it needs without reading the
    table back (:class:`~restitution.sweep.statistics.SweepStatistics`,
    :class:`~restitution.sweep.sobol.SobolCollector`). An interrupt raises
    :class:`SweepInterrupted` with the finished chunks' table.
    """
    if isinstance(spec, dict):
        spec = SweepSpec.from_dict(spec)
    if not in_memory and parts is None:
        raise ValueError("in_memory=False keeps the table on disk: give parts=DIR")
    for name, value in (("chunk_size", chunk_size), ("n_workers", n_workers)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1):
            raise ValueError(f"{name} = {value!r}: expected an integer >= 1")
    spec.check_axes()
    check_case_numbers(spec)
    backend = get_backend(backend, fmu)
    n = spec.n_cases
    keep = keep_columns(columns)
    store = None if parts is None else PartStore(Path(parts))
    run = _Run(spec, backend, keep, store, in_memory, on_chunk)

    if scheduler == "serial":
        default = backend.default_chunk
        if store is None and in_memory and backend.in_memory_chunk:  # nothing on disk: chunks only pace the
            default = _in_memory_chunk(spec, backend)                    # progress and bound the memory
        chunk_size = _chunk_size(store, resume, chunk_size or default)
        chunks = _chunks(n, chunk_size)
        run.open(chunk_size, resume, len(chunks), "this process (serial)", 1)
        payload = backend.local_payload() if isinstance(backend, FmuBackend) else backend.payload()
        bar = _Progress(len(chunks), progress, "serial")
        bar.update(len(run.done))
        # an FMU in this process: Ctrl-C is taken between two FMU calls, never inside one
        deferred = DeferredInterrupt() if isinstance(backend, FmuBackend) else contextlib.nullcontext()
        try:
            with deferred, _fmu_interrupt_check(deferred):
                for a, b in chunks:
                    if a in run.done:
                        continue
                    run.finished(a, b, _run_chunk(a, b, spec, backend, payload, keep))
                    bar.update(len(run.done))
                    if isinstance(deferred, DeferredInterrupt):
                        deferred.check()
        except KeyboardInterrupt:
            bar.close(len(run.done))
            raise run.interrupted() from None
        except BaseException:  # an I/O error writing a part, ...: the error goes on a line of its own
            bar.abandon()
            raise
        finally:
            if isinstance(backend, FmuBackend) and release:
                release_fmus()
        bar.close(len(run.done))
        return run.result()

    with open_client(scheduler, n_workers) as client:
        workers = count_workers(client)
        if chunk_size is None:
            chunk_size = max(1, min(backend.default_chunk, math.ceil(n / (4 * workers))))
        chunk_size = _chunk_size(store, resume, chunk_size)
        chunks = _chunks(n, chunk_size)
        run.open(chunk_size, resume, len(chunks), describe_client(client, scheduler), workers)
        todo = [(a, b) for a, b in chunks if a not in run.done]
        bar = _Progress(len(chunks), progress, "dask")
        bar.update(len(run.done))
        futures = {}  # in flight: key -> future
        payload = None
        transfer = _TransferInterrupt().__enter__()  # left in the finally clause
        try:
            payload = backend.payload()
            if payload is not None and todo:
                with transfer.held():
                    payload = client.scatter([payload], broadcast=True, hash=False)[0]
            from distributed import as_completed

            # At most IN_FLIGHT_PER_WORKER chunks per worker are submitted at a time, the next one when
            # one is taken: finished chunks wait in the workers' memory until this process takes them,
            # so with every chunk submitted at once a sweep that this process writes more slowly than
            # the workers compute held its whole table in the workers (10^8 cases: 16 GB).
            pending = iter(todo)
            bounds = {}
            finished = as_completed()

            def submit_next():
                ab = next(pending, None)
                if ab is not None:
                    future = client.submit(_run_chunk, *ab, spec=spec, backend=backend, payload=payload,
                                           keep=keep, packed=True, pure=False)
                    futures[future.key], bounds[future.key] = future, ab
                    finished.add(future)

            for _ in range(IN_FLIGHT_PER_WORKER * workers):
                submit_next()
            for future in finished:
                a, b = bounds.pop(future.key)
                with transfer.held():
                    part = future.result()
                futures.pop(future.key)
                future.release()
                submit_next()  # before this chunk is handled (written to the parts): no worker waits for it
                run.finished(a, b, part)
                bar.update(len(run.done))
        except KeyboardInterrupt:
            bar.close(len(run.done))
            with contextlib.suppress(Exception):
                client.cancel(list(futures.values()))
            raise run.interrupted() from None
        except BaseException:
            bar.abandon()
            raise
        finally:
            transfer.__exit__()
            with contextlib.suppress(Exception):
                client.cancel(list(futures.values()))
            if isinstance(backend, FmuBackend) and release:
                with contextlib.suppress(Exception):
                    # an instance still busy with a cancelled chunk is freed after it; see _RELEASE_ON_WORKER
                    client.run(exec, _RELEASE_ON_WORKER, {})
            if hasattr(payload, "release"):
                with contextlib.suppress(Exception):
                    client.cancel([payload])
        bar.close(len(run.done))
        return run.result()


#: Run on each worker at the end of an FMU sweep: ``release_fmus()`` if the worker loaded the back end (sent
#: as source to the builtin ``exec``: a function would be unpickled by importing its module, on every
#: worker). release_fmus() waits for an instantiation under way (its lock).
_RELEASE_ON_WORKER = """
import sys
backends = sys.modules.get("restitution.sweep.backends")
if backends is not None:
    backends.release_fmus()
"""


class _TransferInterrupt(DeferredInterrupt):
    """Ctrl-C at once, except while data travels between this process and the workers (:meth:`held`:
    a chunk taken from its worker, the payload scattered): then just after it. Raised in mid-transfer, the
    KeyboardInterrupt cancelled the transfer and closed its connection, and the worker logged
    ``distributed.worker - ERROR - failed during get data`` with a CommClosedError traceback."""

    holding = False

    def _note(self, signum, frame):
        if not self.holding:
            raise KeyboardInterrupt
        super()._note(signum, frame)  # a second Ctrl-C during the transfer: at once

    @contextlib.contextmanager
    def held(self):
        self.holding = True
        try:
            yield
        finally:
            self.holding = False
        self.check()


class _Run:
    """The finished chunks of one run (start -> (columns or None, info)): written to ``store`` as they
    finish, shown to ``on_chunk`` (see :func:`run_sweep`) and, when ``in_memory``, copied into the table
    at once (:class:`~restitution.sweep.table.TableBuilder`; the columns of chunks reused from the parts
    wait in ``done`` until the table is taken)."""

    def __init__(self, spec, backend, keep, store, in_memory: bool, on_chunk=None):
        self.spec, self.backend, self.keep, self.store, self.in_memory = spec, backend, keep, store, in_memory
        self.on_chunk = on_chunk
        self.done = {}
        self.builder = TableBuilder(spec, keep, spec.n_cases) if in_memory else None

    def open(self, chunk_size, resume, n_chunks, where, workers):
        self.n_chunks, self.where, self.workers = n_chunks, where, workers
        if self.store is not None:
            self.done = self.store.open(self.spec, self.backend, chunk_size, self.keep, resume,
                                        load_columns=self.in_memory, on_chunk=self.on_chunk)
        self.reused = dict.fromkeys(self.done)  # kept from the parts (--resume): not in the rate
        self.t0 = time.perf_counter()

    def finished(self, a, b, part):
        """Chunk ``a`` ... ``b - 1`` written, shown to ``on_chunk`` and recorded as done, with Ctrl-C
        held until all three are: cut in between, the interrupted table left out a chunk whose part
        was on disk (or the statistics a chunk that the table has)."""
        columns, info = part
        plain = columns.columns() if isinstance(columns, PackedColumns) else columns  # views: no copy
        held = DeferredInterrupt(over_any_handler=True)
        with held:
            if self.store is not None:
                self.store.write(a, b, (plain, info))
            if self.on_chunk is not None:
                self.on_chunk(a, b, plain)
            if self.in_memory:
                self.builder.add(a, columns)
            self.done[a] = (None, info)
        held.check()

    def result(self) -> SweepResult:
        """The table of the finished chunks (their columns are consumed: call once)."""
        elapsed = time.perf_counter() - self.t0
        starts = sorted(self.done)
        info = _info(self.backend, [self.done[a][1] for a in starts])
        if self.reused:
            info["reused"] = {"chunks": len(self.reused), "from": str(self.store.path),
                              "cases": sum(int(self.done[a][1]["counts"]["cases"]) for a in self.reused)}
        kwargs = dict(spec=self.spec, backend=self.backend.describe(), scheduler=self.where, n_workers=self.workers,
                      elapsed=elapsed, n_chunks=self.n_chunks, info=info)
        if self.store is not None:  # the table is written from the parts
            info["keep"], info["sweep"] = self.keep, self.store.sweep
            kwargs.update(parts=Path(self.store.path), chunk_counts={a: self.done[a][1]["counts"] for a in starts})
        if self.in_memory:
            for a in starts:
                if self.done[a][0] is not None:  # reused from the parts
                    self.builder.add(a, self.done[a][0])
                    self.done[a] = (None, self.done[a][1])
            return SweepResult(columns=self.builder.table(), **kwargs)
        return DiskSweepResult(columns={}, **kwargs)

    def interrupted(self) -> "SweepInterrupted":
        result = self.result()
        return SweepInterrupted(result, self.spec.n_cases - len(result))


@contextlib.contextmanager
def _fmu_interrupt_check(deferred):
    """The FMU back end checks ``deferred`` between cases while it is in force (serial runs)."""
    from . import backends

    if not isinstance(deferred, DeferredInterrupt):
        yield
        return
    backends._INTERRUPT_CHECK = deferred.check
    try:
        yield
    finally:
        backends._INTERRUPT_CHECK = None


def _chunk_size(store, resume: bool, chunk_size: int) -> int:
    """The chunk size: a resumed run keeps the one its parts were cut with."""
    if store is not None and resume:
        manifest = store.manifest()
        if manifest is not None:
            return int(manifest["chunk_size"])
    return int(chunk_size)


class _Progress:
    """Chunks done, on stderr: redrawn in a terminal once the run has taken a second; when
    redirected, nothing but the final state (``close``), always on a line of its own."""

    def __init__(self, total: int, enabled: bool, label: str):
        self.total, self.enabled, self.label = total, enabled, label
        self.tty = enabled and sys.stderr.isatty()
        self.t0 = time.perf_counter()
        self.drawn = False

    def update(self, done: int) -> None:
        if self.tty and time.perf_counter() - self.t0 >= 1.0:
            print(f"\r[{self.label}] {done}/{self.total} chunks", end="", file=sys.stderr, flush=True)
            self.drawn = True

    def abandon(self) -> None:
        """End a redrawn line (an error follows on its own line)."""
        if self.drawn:
            print(file=sys.stderr, flush=True)
            self.drawn = False

    def close(self, done: int) -> None:
        if not self.enabled:
            return
        end = "\r" if self.drawn else ""
        sys.stdout.flush()  # what was printed before stays before, when both go to one file
        print(f"{end}[{self.label}] {done}/{self.total} chunks done in {time.perf_counter() - self.t0:.3g} s",
              file=sys.stderr, flush=True)


def _info(backend, infos) -> dict:
    codes = sorted({i["code"] for i in infos})
    info = {"code": codes, "processes": len({i["pid"] for i in infos}),
            "cpu_seconds": float(sum(i["cpu"] for i in infos)), "client_code": code_fingerprint()}
    if "fmu_code_file" in (infos[0] if infos else {}):
        info["fmu_code_files"] = sorted({i["fmu_code_file"] for i in infos})
    if backend.name == "package" and codes and codes != [info["client_code"]]:
        warnings.warn(f"the workers ran restitution code {codes}, this process has {info['client_code']}: "
                      f"install the same restitution on the workers", RuntimeWarning, stacklevel=4)
    return info
