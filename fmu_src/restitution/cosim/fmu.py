"""A named-variable wrapper around ``fmpy.fmi2.FMU2Slave`` for the project's FMUs."""
from __future__ import annotations

import shutil
import weakref
from pathlib import Path

__all__ = ["FmuInstance", "FmiStatusError", "build_default_fmu", "impact_fmu_parameters"]


class FmiStatusError(RuntimeError):
    """An FMI call returned a status other than fmi2OK (fmi2Discard, fmi2Error, ...)."""

    def __init__(self, message: str, status: int | None = None):
        super().__init__(message)
        self.status = status


def build_default_fmu(out_dir: str | Path | None = None, model: str = "SpherePlateImpact",
                      rebuild: bool = False, log=None) -> Path:
    """Path of ``<model>.fmu``, built when missing or stale: :func:`restitution.fmu.default_fmu`."""
    from ..fmu.build import default_fmu

    return default_fmu(out_dir, model=model, rebuild=rebuild, log=log)


def impact_fmu_parameters(sphere, plate) -> dict:
    """FMU parameter values (by FMI name) for a :class:`~restitution.Sphere` and :class:`~restitution.Plate`."""
    from ..fmu.models.sphere_plate_impact.variables import fmu_values

    return fmu_values(**sphere.params(), **plate.params())


# fmpy's native logger proxy (which formats the variadic C message) keeps one logger for the
# whole process, so one callback serves every instance and routes by instance name.
_LOG_ROUTES: "weakref.WeakValueDictionary[str, FmuInstance]" = weakref.WeakValueDictionary()
_CALLBACKS = None


def _register(name: str, instance) -> str:
    unique, n = name, 1
    while unique in _LOG_ROUTES:
        n += 1
        unique = f"{name}#{n}"
    _LOG_ROUTES[unique] = instance
    return unique


def _shared_callbacks():
    global _CALLBACKS
    if _CALLBACKS is None:
        from ctypes import byref
        from fmpy.fmi2 import (calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free, printLogMessage)
        from fmpy.logging import addLoggerProxy

        def log(component, instance_name, status, category, message):
            name = instance_name.decode("utf-8", "replace") if instance_name else ""
            target = _LOG_ROUTES.get(name)
            if target is None:
                printLogMessage(component, instance_name, status, category, message)
            else:
                target._receive_log(int(status), message.decode("utf-8", "replace") if message else "")

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(log)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(callbacks))
        _CALLBACKS = callbacks
    return _CALLBACKS


class FmuInstance:
    """One co-simulation instance of an FMU, addressed by variable name.

    >>> with FmuInstance("dist/SpherePlateImpact.fmu") as fmu:
    ...     fmu.set(v_approach=2.3)
    ...     fmu.do_step(0.0, 1e-3)
    ...     e, = fmu.get("e")

    ``unzip_dir`` lets several instances share one extraction; ``logger(status, message)``
    receives the FMU's log messages (default: collected in :attr:`messages`); ``logging_on=False``
    asks the FMU for warnings and errors only (fmi2Instantiate's loggingOn), as a timing loop wants.
    ``instantiate(slave)``, when given, calls fmi2Instantiate on the ``fmpy.fmi2.FMU2Slave`` instead
    (its own callbacks and module set-up: the sweep's FMU back end); ``fmu_path`` may be an unzipped FMU.
    """

    def __init__(self, fmu_path, instance_name: str = "instance", unzip_dir=None, logger=None,
                 start_time: float = 0.0, parameters: dict | None = None, logging_on: bool = True,
                 instantiate=None):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.path = Path(fmu_path)
        self.model_description = read_model_description(str(self.path))
        self._own_dir = unzip_dir is None
        self.unzip_dir = extract(str(self.path)) if unzip_dir is None else str(unzip_dir)
        self.variables = {v.name: v for v in self.model_description.modelVariables}
        self.messages: list[tuple[int, str]] = []
        self._logger = logger
        self.instance_name = _register(instance_name, self)
        self._slave = FMU2Slave(guid=self.model_description.guid, unzipDirectory=self.unzip_dir,
                                modelIdentifier=self.model_description.coSimulation.modelIdentifier,
                                instanceName=self.instance_name)
        if instantiate is None:
            self._slave.instantiate(loggingOn=logging_on, callbacks=self._make_callbacks())
        else:
            instantiate(self._slave)
        self.time = start_time
        try:
            self._call(lambda: self._slave.setupExperiment(startTime=start_time))
            self._call(self._slave.enterInitializationMode)
            if parameters:
                self.set(**parameters)
            self._call(self._slave.exitInitializationMode)
        except BaseException:  # a refused parameter: free the instance, then say why
            self._slave.freeInstance()
            self._slave = None
            _LOG_ROUTES.pop(self.instance_name, None)
            if self._own_dir:
                shutil.rmtree(self.unzip_dir, ignore_errors=True)
            raise

    def _make_callbacks(self):
        return _shared_callbacks()

    def _receive_log(self, status: int, text: str):
        self.messages.append((status, text))
        if self._logger is not None:
            self._logger(status, text)

    # --- variables ------------------------------------------------------------------
    def vr(self, name: str) -> int:
        return self.variables[name].valueReference

    def set(self, **values):
        """Set variables by name; dotted FMI names are passed as ``**{"sphere.E": 2e11}``, an Enumeration
        by its item's name or code (``**{"plate.material": "al_6061"}``). A value the FMU refuses raises
        FmiStatusError (status fmi2Error, the FMU's message): the FMU keeps the previous values of the
        call's variables of that type."""
        reals, ints, bools = {}, {}, {}
        for name, value in values.items():
            kind = self.variables[name].type
            if kind == "Enumeration" and isinstance(value, str):
                value = self.item_code(name, value)
            target = reals if kind == "Real" else ints if kind in ("Integer", "Enumeration") else bools
            target[self.vr(name)] = value
        if reals:
            self._call(self._slave.setReal, list(reals), [float(v) for v in reals.values()])
        if ints:
            self._call(self._slave.setInteger, list(ints), [int(v) for v in ints.values()])
        if bools:
            self._call(self._slave.setBoolean, list(bools), [bool(v) for v in bools.values()])

    def item_code(self, name: str, item: str) -> int:
        """The code of the item ``item`` of the Enumeration variable ``name`` (ValueError listing the items)."""
        items = {i.name: int(i.value) for i in self.variables[name].declaredType.items}
        if item not in items:
            raise ValueError(f"{name} = {item!r} is not one of its items: {', '.join(items)}")
        return items[item]

    def _call(self, function, *args):
        """An fmpy call; a status above fmi2Warning becomes FmiStatusError with the FMU's last message."""
        try:
            return function(*args)
        except Exception as exc:  # fmpy raises on any status above fmi2Warning
            status = getattr(exc, "status", None)
            if status is None:
                raise
            raise FmiStatusError(f"{exc}; FMU log: {self.last_message()}", status) from exc

    def get(self, *names):
        """Values of the named variables, in order (Reals as float, Booleans as bool)."""
        out = []
        for name in names:
            var = self.variables[name]
            if var.type == "Real":
                out.append(self._call(self._slave.getReal, [var.valueReference])[0])
            elif var.type in ("Integer", "Enumeration"):
                out.append(self._call(self._slave.getInteger, [var.valueReference])[0])
            else:
                out.append(bool(self._call(self._slave.getBoolean, [var.valueReference])[0]))
        return out

    def get_reals(self, names) -> list[float]:
        """Several Reals in one fmi2GetReal call (the fast path for hot loops)."""
        return self._call(self._slave.getReal, [self.vr(n) for n in names])

    # --- stepping ---------------------------------------------------------------------
    def do_step(self, current_time: float | None = None, step_size: float = 0.0):
        """fmi2DoStep; raises FmiStatusError on fmi2Discard/fmi2Error (the FMU's log says why)."""
        t = self.time if current_time is None else current_time
        self._call(self._slave.doStep, t, step_size)
        self.time = t + step_size

    def last_message(self) -> str:
        return self.messages[-1][1] if self.messages else ""

    def reset(self):
        self._slave.reset()
        self._slave.setupExperiment(startTime=0.0)
        self._slave.enterInitializationMode()
        self._slave.exitInitializationMode()
        self.time = 0.0

    @property
    def slave(self):
        """The underlying ``fmpy.fmi2.FMU2Slave`` (state get/set, raw calls)."""
        return self._slave

    def close(self):
        if self._slave is None:
            return
        try:
            self._slave.terminate()
        finally:
            self._slave.freeInstance()
            self._slave = None
            _LOG_ROUTES.pop(self.instance_name, None)
            if self._own_dir:
                shutil.rmtree(self.unzip_dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
