"""The Dask side of a sweep: a client (an existing scheduler, or a LocalCluster sized to this machine
whose workers ignore Ctrl-C and do not inherit pythonfmu's sys.path entries) and what it is."""
from __future__ import annotations

import contextlib
import os

__all__ = ["machine_workers", "open_client", "count_workers", "describe_client", "serial_reason"]

def machine_workers() -> int:
    """Worker processes for a local cluster: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


@contextlib.contextmanager
def open_client(scheduler=None, n_workers: int | None = None, threads_per_worker: int = 1, **cluster_kwargs):
    """A ``distributed.Client`` for a sweep, closed (with any cluster it started) on exit.

    ``scheduler``: a ``Client`` (used as is, left open), a scheduler address
    (``"tcp://host:8786"``), or None / ``"local"``: the scheduler named by Dask's config
    (``DASK_SCHEDULER_ADDRESS``) if set, else a new ``LocalCluster`` of ``n_workers``
    single-threaded processes (default: one per core).
    """
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler in (None, "local"):
        import dask

        address = dask.config.get("scheduler-address", None) if scheduler is None else None
        if address:
            scheduler = address
    if scheduler not in (None, "local"):
        with Client(scheduler) as client:
            yield client
        return
    import logging  # (here: a serial sweep never loads it)

    kwargs = dict(n_workers=n_workers or machine_workers(), threads_per_worker=threads_per_worker,
                  processes=True, dashboard_address=None, silence_logs=logging.ERROR)
    kwargs.update(cluster_kwargs)
    # the workers start with this process's sys.path, ignoring Ctrl-C (see _workers_ignore_sigint), and
    # with glibc's own allocation thresholds (see _workers_keep_glibc_thresholds)
    with _workers_ignore_sigint() as release:
        with _without_fmu_resources_on_sys_path(), _workers_keep_glibc_thresholds():
            cluster = LocalCluster(**kwargs)
        # direct_to_workers: this process takes each finished chunk from its worker. Through the scheduler
        # (Dask's default for a client) every chunk crossed TCP twice and, the LocalCluster's scheduler
        # living in this process, was received here twice, into fresh memory each time.
        with _quiet_shutdown() as quiet, cluster, Client(cluster, direct_to_workers=True) as client:
            release()  # a Ctrl-C of the start-up is raised here, where the cluster is closed on the way out
            try:
                yield client
            finally:
                quiet(client)


def _silence_logging() -> None:
    """No more log records in this process (a worker about to be stopped)."""
    import logging

    logging.disable(logging.CRITICAL)


@contextlib.contextmanager
def _quiet_shutdown():
    """``quiet(client)``, called before the cluster closes: no more logs from its workers, nor from Dask in
    this process until the cluster is closed (the level is put back on the way out).

    The cluster stops its scheduler (in this process) and its workers one after the other; a worker whose
    heartbeat found the scheduler gone logged a traceback to the terminal after the sweep's own last line
    (seen after an interrupt on a loaded machine). Whatever the sweep had to say is said by then; a failure
    to reach a worker here is of no consequence (it is being stopped)."""
    import logging

    logger = logging.getLogger("distributed")
    level = logger.level

    def quiet(client):
        with contextlib.suppress(Exception):
            client.run(_silence_logging, on_error="ignore")
        logger.setLevel(logging.CRITICAL)
    try:
        yield quiet
    finally:
        logger.setLevel(level)


@contextlib.contextmanager
def _workers_keep_glibc_thresholds():
    """The worker processes start without Dask's MALLOC_TRIM_THRESHOLD_=65536.

    Setting any glibc malloc threshold switches off its dynamic mmap threshold, so every array over
    128 KiB is mapped fresh and page-faulted on each allocation: a package chunk of 100,000 cases took
    2.1x the CPU time in a worker that it takes in this process (measured: 62 vs 29 ms). A chunk's
    arrays are freed and reallocated at the same sizes, so glibc's default keeps them for reuse; the
    memory a worker holds stays bounded by one chunk's working set."""
    import dask

    environ = {key: value for key, value in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
               if key != "MALLOC_TRIM_THRESHOLD_"}
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):
        yield


@contextlib.contextmanager
def _workers_ignore_sigint():
    """SIGINT blocked in this thread while a LocalCluster starts, and noted, not raised, until
    ``release()`` (called once the cluster can be closed again) raises it.

    Ctrl-C in a terminal reaches every process of the foreground group: the workers' event loops
    would die with a KeyboardInterrupt traceback each, and an FMU back end's worker would take it
    inside an FMU call (fmi2Fatal). The threads the cluster starts here inherit this thread's signal
    mask, and the worker processes they spawn inherit theirs, so SIGINT stays blocked in the workers
    for good. The client process alone takes Ctrl-C: it cancels the tasks, keeps the finished chunks
    and closes the cluster, which stops the workers. SIGINT used to be ignored (SIG_IGN) during the
    start instead: a Ctrl-C of those seconds was lost (the numpy/OpenBLAS threads, which do not block
    it, took it and the kernel discarded it) and the sweep ran to its end; raised mid-start, it would
    leave half a cluster."""
    import signal
    import threading

    if not hasattr(signal, "pthread_sigmask"):  # not POSIX: no process group to share Ctrl-C with
        yield lambda: None
        return
    from multiprocessing import resource_tracker

    # started now, not by the first worker's spawn: starting it unblocks SIGINT in the spawning thread
    resource_tracker.ensure_running()
    noted = []
    handler = None
    if threading.current_thread() is threading.main_thread():
        handler = signal.signal(signal.SIGINT, lambda signum, frame: noted.append(signum))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})

    def release():
        nonlocal handler
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        if handler is not None:
            signal.signal(signal.SIGINT, handler)
            handler = None
            if noted:
                raise KeyboardInterrupt
    try:
        yield release
    finally:
        release()


@contextlib.contextmanager
def _without_fmu_resources_on_sys_path():
    """sys.path minus the resources/ directories of pythonfmu FMUs loaded in this process.

    pythonfmu prepends an FMU's resources/ to sys.path when it instantiates it; worker processes
    started afterwards would inherit that entry and import the FMU's physics-only copy of
    ``restitution`` (no ``restitution.sweep``) instead of this one, and die.
    """
    import sys

    saved = list(sys.path)
    sys.path[:] = [p for p in saved if not (p and os.path.isfile(os.path.join(p, "slavemodule.txt")))]
    try:
        yield
    finally:
        sys.path[:] = saved


def count_workers(client) -> int:
    try:
        info = client.scheduler_info(n_workers=-1)
    except TypeError:  # distributed before 2025.4 lists every worker anyway
        info = client.scheduler_info()
    return max(1, len(info["workers"]))


def describe_client(client, scheduler) -> str:
    from distributed import LocalCluster

    if isinstance(getattr(client, "cluster", None), LocalCluster) and not isinstance(scheduler, str):
        return f"a LocalCluster ({client.scheduler.address})"
    return f"the Dask scheduler at {client.scheduler.address}"


#: What a LocalCluster costs before it computes anything, measured on the project's 2-core machine
#: (shared, load about 1.7; 2026-11): started and closed in a process 2.1 ... 2.5 s, and a whole
#: 160-case command took 2.5 ... 3.5 s with --scheduler local against 0.65 s with --scheduler serial.
CLUSTER_SECONDS = 2.5
#: Seconds a case takes serially in this process, per back end (same machine, medians of 3): default
#: options; plate_waves = on; zener_method = ode (the integrated Zener model, whatever else is set).
CASE_SECONDS = {"package": (0.3e-6, 5e-6, 6e-3), "fmu": (60e-6, 320e-6, 6e-3)}


def serial_reason(spec, backends, n_workers: int | None = None) -> str | None:
    """Why a sweep given no scheduler (no --scheduler, no ``DASK_SCHEDULER_ADDRESS``) runs serially in
    this process, or None when a LocalCluster may pay for itself: ``W`` workers save at most a fraction
    ``1 - 1/W`` of the serial time, which must exceed :data:`CLUSTER_SECONDS`. With the measured
    costs and 2 workers: up to about 16.7 million cases with the package back end, 83,000 with the
    FMU, 830 with zener_method = ode."""
    import dask

    if dask.config.get("scheduler-address", None):
        return None
    workers = n_workers or machine_workers()
    seconds = spec.n_cases * sum(CASE_SECONDS[name][cost_class(spec)] for name in backends)
    if seconds * (1 - 1 / workers) >= CLUSTER_SECONDS:
        return None
    return (f"serial: about {seconds:.2g} s of work, too little for a LocalCluster of {workers} worker(s) to win "
            f"back its {CLUSTER_SECONDS:g} s start; --scheduler local starts one")


def cost_class(spec) -> int:
    """0, 1 or 2: which column of :data:`CASE_SECONDS` the options that the sweep may take select."""
    from .spec import CODES, START

    def may_be(name, code):
        if name in spec._fixed:
            values = spec._fixed[name]
        elif name in spec.grid:
            values = spec.axes[name]
        elif name in spec.distributions:
            kind, args = spec.distributions[name]
            values = args if kind == "choice" else (code,)  # a continuous draw of a code: assume the worst
        else:
            values = (START[name],)
        return any(float(v) == code for v in values)
    if may_be("zener_method", CODES["zener_method"]["ode"]):
        return 2
    return 1 if may_be("plate_waves", CODES["plate_waves"]["on"]) else 0
