"""A named-variable wrapper around fmpy's ``FMU2Slave`` and ``FMU3Slave`` for the project's FMUs (FMI 2.0 and 3.0)."""
from __future__ import annotations

import shutil
import weakref
from pathlib import Path

__all__ = ["FmuInstance", "FmiStatusError", "check_impact_fmu", "read_fmu_description", "impact_fmu_parameters",
           "quiet_instantiate"]


class FmiStatusError(RuntimeError):
    """An FMI call returned a status above Warning: 2 Discard, 3 Error, 4 Fatal (the same codes in FMI 2.0 and 3.0)."""

    def __init__(self, message: str, status: int | None = None):
        super().__init__(message)
        self.status = status


def read_fmu_description(path, option: str) -> tuple:
    """(``path`` as a Path, its modelDescription read by fmpy) for an FMU given as ``option``; ValueError, one
    line naming ``option`` and the path, where it is no file or no FMU fmpy can read."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{option} {path}: {'not a file' if path.exists() else 'no such file'}")
    try:
        from fmpy import read_model_description

        return path, read_model_description(str(path))
    except Exception as exc:  # noqa: BLE001 - whatever the archive is, it is not an FMU we can read
        raise ValueError(f"{option} {path}: not an FMU ({type(exc).__name__}: {exc})") from None


def check_impact_fmu(path, option: str = "--fmu") -> Path:
    """``path`` if it is a SpherePlateImpact FMU (a file, an FMU archive with a co-simulation interface and
    every input, parameter and output of the model's interface table, which sweeps and scenes use); else
    ValueError, one line naming ``option`` and the path."""
    from ..fmu.models import table

    path, md = read_fmu_description(path, option)
    names = {v.name for v in md.modelVariables}
    missing = [row.name for row in table("SpherePlateImpact")
               if row.causality in ("input", "parameter", "output") and row.name not in names]
    if missing or md.coSimulation is None:
        what = f"no variable(s) {', '.join(missing[:4])}{' ...' if len(missing) > 4 else ''}" if missing else \
            "no co-simulation interface"
        raise ValueError(f"{option} {path}: not a SpherePlateImpact FMU ({md.modelName}: {what})")
    return path


def impact_fmu_parameters(sphere, plate) -> dict:
    """FMU parameter values (by FMI name) for a :class:`~restitution.Sphere` and :class:`~restitution.Plate`."""
    from ..fmu.models.sphere_plate_impact.variables import fmu_values

    return fmu_values(**sphere.params(), **plate.params())


# --- what differs between FMI 2.0 and FMI 3.0 (and nothing else) ---------------------------------

# fmpy's native logger proxy (which formats the variadic C message) keeps one logger for the
# whole process, so one FMI 2.0 callback serves every instance and routes by instance name.
_LOG_ROUTES: "weakref.WeakValueDictionary[str, FmuInstance]" = weakref.WeakValueDictionary()
_CALLBACKS = None
_QUIET_CALLBACKS = None


def _register(name: str, instance) -> str:
    unique, n = name, 1
    while unique in _LOG_ROUTES:
        n += 1
        unique = f"{name}#{n}"
    _LOG_ROUTES[unique] = instance
    return unique


def _text(message) -> str:
    return message.decode("utf-8", "replace") if message else ""


def _fmi2_callbacks(quiet: bool):
    global _CALLBACKS, _QUIET_CALLBACKS
    if (_QUIET_CALLBACKS if quiet else _CALLBACKS) is None:
        from ctypes import byref
        from fmpy.fmi2 import (calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free, printLogMessage)
        from fmpy.logging import addLoggerProxy

        def log(component, instance_name, status, category, message):
            target = _LOG_ROUTES.get(_text(instance_name))
            if target is None:
                printLogMessage(component, instance_name, status, category, message)
            else:
                target._receive_log(int(status), _text(message))

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda *args: None) if quiet else fmi2CallbackLoggerTYPE(log)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        if quiet:
            _QUIET_CALLBACKS = callbacks
        else:
            addLoggerProxy(byref(callbacks))
            _CALLBACKS = callbacks
    return _QUIET_CALLBACKS if quiet else _CALLBACKS


class _Fmi2:
    """FMI 2.0 through ``fmpy.fmi2.FMU2Slave``."""

    version = "2.0"
    prefix = "fmi2"
    #: modelDescription type -> (fmi2Get/Set function suffix, ctypes value type name in fmpy.fmi2)
    types = {"Real": ("Real", "fmi2Real"), "Integer": ("Integer", "fmi2Integer"),
             "Enumeration": ("Integer", "fmi2Integer"), "Boolean": ("Boolean", "fmi2Boolean")}
    counted = False  # fmi2Get/Set take no count of values
    #: fmpy's names of get, set, free, serialize, deserialize an FMU state
    state = ("getFMUstate", "setFMUstate", "freeFMUstate", "serializeFMUstate", "deSerializeFMUstate")

    @staticmethod
    def module():
        from fmpy import fmi2
        return fmi2

    @staticmethod
    def slave(md, unzip_dir, name):
        from fmpy.fmi2 import FMU2Slave
        return FMU2Slave(guid=md.guid, unzipDirectory=unzip_dir, modelIdentifier=md.coSimulation.modelIdentifier,
                         instanceName=name)

    @staticmethod
    def instantiate(slave, logging_on: bool, instance):
        slave.instantiate(loggingOn=logging_on, callbacks=_fmi2_callbacks(quiet=instance is None))

    @staticmethod
    def enter_initialization(slave, start_time: float):
        slave.setupExperiment(startTime=start_time)
        slave.enterInitializationMode()

    @staticmethod
    def stepper(slave):
        do_step, component = slave.fmi2DoStep, slave.component

        def step(t, h, no_state_before):
            do_step(component, t, h, no_state_before)
        return step


class _Fmi3:
    """FMI 3.0 through ``fmpy.fmi3.FMU3Slave``: Float64/Int32/Boolean, Enumerations through Int64, the
    start time given to fmi3EnterInitializationMode, fmi3DoStep's out-arguments, a logger per instance
    (its messages are plain strings, and it receives no instance name)."""

    version = "3.0"
    prefix = "fmi3"
    types = {"Float64": ("Float64", "fmi3Float64"), "Int32": ("Int32", "fmi3Int32"),
             "Enumeration": ("Int64", "fmi3Int64"), "Boolean": ("Boolean", "fmi3Boolean")}
    counted = True  # fmi3Get/Set take the number of values after the values
    state = ("getFMUState", "setFMUState", "freeFMUState", "serializeFMUState", "deserializeFMUState")

    @staticmethod
    def module():
        from fmpy import fmi3
        return fmi3

    @staticmethod
    def slave(md, unzip_dir, name):
        from fmpy.fmi3 import FMU3Slave
        return FMU3Slave(guid=md.instantiationToken, unzipDirectory=unzip_dir,
                         modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)

    @staticmethod
    def instantiate(slave, logging_on: bool, instance):
        if instance is None:
            def log(env, status, category, message):
                pass
        else:
            target = weakref.ref(instance)

            def log(env, status, category, message):
                receiver = target()
                if receiver is not None:
                    receiver._receive_log(int(status), _text(message))
        slave.instantiate(loggingOn=logging_on, logMessage=log)  # fmpy keeps the C callback on the slave

    @staticmethod
    def enter_initialization(slave, start_time: float):
        slave.enterInitializationMode(startTime=start_time)

    @staticmethod
    def step_call(slave):
        """fmi3DoStep as ``step(t, h, no_state_before)``, its out-arguments in ``out``: eventHandlingNeeded,
        terminateSimulation, earlyReturn, lastSuccessfulTime (ctypes values, allocated once)."""
        from ctypes import byref, c_bool, c_double

        do_step, component = slave.fmi3DoStep, slave.component
        out = (c_bool(), c_bool(), c_bool(), c_double())
        refs = tuple(byref(x) for x in out)

        def step(t, h, no_state_before):
            do_step(component, t, h, no_state_before, *refs)
        return step, out

    @staticmethod
    def stepper(slave):
        call, (_event, terminate, early, last) = _Fmi3.step_call(slave)

        def step(t, h, no_state_before):
            call(t, h, no_state_before)
            if terminate.value or early.value:  # never without earlyReturnAllowed (restitution.cosim.event_mode)
                raise FmiStatusError(f"fmi3DoStep({t!r}, {h!r}) returned early at {last.value!r} s "
                                     f"(terminateSimulation = {terminate.value})", 2)
        return step


def _version_of(model_description):
    return _Fmi3 if model_description.fmiVersion.startswith("3") else _Fmi2


#: Every modelDescription type, as the kind this wrapper reports for both FMI versions (FMI 2.0's names).
KINDS = {"Real": "Real", "Float64": "Real", "Float32": "Real", "Integer": "Integer", "Int32": "Integer",
         "Int64": "Integer", "Enumeration": "Enumeration", "Boolean": "Boolean", "String": "String"}
_KIND_ORDER = ("Real", "Integer", "Enumeration", "Boolean")  # the order set() calls the setters in


def quiet_instantiate(slave):
    """Instantiate an fmpy slave (FMU2Slave or FMU3Slave) with logging off and a logger that drops every
    message: for an ``instantiate`` hook of :class:`FmuInstance` that needs no log (the sweep)."""
    from fmpy.fmi3 import FMU3Slave

    (_Fmi3 if isinstance(slave, FMU3Slave) else _Fmi2).instantiate(slave, False, None)


class _Variables(dict):
    """The model's variables by name; an unknown name is a KeyError naming the model and the closest
    names (a parameter misspelled in ``FmuInstance(parameters=...)`` or ``set()``)."""

    def __init__(self, model: str, variables: dict):
        super().__init__(variables)
        self.model = model

    def __missing__(self, name):
        import difflib

        close = difflib.get_close_matches(str(name), list(self), n=3)
        if not close:  # a word of the name in a variable's name: "plate.thickness" -> plate.t, plate.E, ...
            words = [w for w in str(name).replace("_", ".").split(".") if len(w) >= 3]
            close = [v for v in self if any(w.lower() in v.lower() for w in words)][:3]
        hint = f" (did you mean {' or '.join(repr(c) for c in close)}?)" if close else ""
        raise KeyError(f"{self.model} has no variable {name!r}{hint}")


class FmuInstance:
    """One co-simulation instance of an FMI 2.0 or FMI 3.0 FMU, addressed by variable name.

    >>> with FmuInstance("dist/SpherePlateImpact.fmu") as fmu:
    ...     fmu.set(v_approach=2.3)
    ...     fmu.do_step(0.0, 1e-3)
    ...     e, = fmu.get("e")

    The FMI version comes from the modelDescription (:attr:`fmi_version`); nothing here or in the
    callers depends on it: variables are addressed by name, their kinds are FMI 2.0's names
    (:meth:`kind`: an FMI 3.0 Float64 is a "Real"), Enumerations take an item's name or code.
    :meth:`reader` and :meth:`writer` give the fast path for hot loops (one FMI call per variable
    type, arrays allocated once); :meth:`get_state` and its siblings save and restore FMU states.

    ``unzip_dir`` lets several instances share one extraction; ``logger(status, message)``
    receives the FMU's log messages (default: collected in :attr:`messages`); ``logging_on=False``
    asks the FMU for warnings and errors only (the instantiate call's loggingOn), as a timing loop wants.
    ``instantiate(slave)``, when given, instantiates the fmpy slave (``FMU2Slave`` or ``FMU3Slave``)
    instead (its own callbacks and module set-up: the sweep's FMU back end, with
    :func:`quiet_instantiate`); ``fmu_path`` may be an unzipped FMU.
    """

    def __init__(self, fmu_path, instance_name: str = "instance", unzip_dir=None, logger=None,
                 start_time: float = 0.0, parameters: dict | None = None, logging_on: bool = True,
                 instantiate=None):
        from fmpy import extract, read_model_description

        self.path = Path(fmu_path)
        self.model_description = read_model_description(str(self.path))
        self._fmi = self._interface()
        self._own_dir = unzip_dir is None
        self.unzip_dir = extract(str(self.path)) if unzip_dir is None else str(unzip_dir)
        self.variables = _Variables(self.model_description.modelName,
                                    {v.name: v for v in self.model_description.modelVariables})
        self.messages: list[tuple[int, str]] = []
        self._logger = logger
        self._readers: dict = {}
        self._writers: dict = {}
        self._held_states = 0  # FMU states got and not freed: a step may be followed by a restore
        self.instance_name = _register(instance_name, self)
        self._slave = self._fmi.slave(self.model_description, self.unzip_dir, self.instance_name)
        if instantiate is None:
            self._fmi.instantiate(self._slave, logging_on, self)
        else:
            instantiate(self._slave)
        self._step = self._fmi.stepper(self._slave)
        try:
            self._initialize(start_time, parameters)
        except BaseException:  # a refused parameter: free the instance, then say why
            self._slave.freeInstance()
            self._slave = None
            _LOG_ROUTES.pop(self.instance_name, None)
            if self._own_dir:
                shutil.rmtree(self.unzip_dir, ignore_errors=True)
            raise

    def _interface(self):
        """What differs between the FMI versions (and, in a subclass, the interface: model exchange)."""
        return _version_of(self.model_description)

    @property
    def fmi_version(self) -> str:
        """The FMU's FMI version: "2.0" or "3.0"."""
        return self._fmi.version

    def _initialize(self, start_time: float, parameters: dict | None):
        self.time = start_time
        self._call(self._fmi.enter_initialization, self._slave, start_time)
        if parameters:
            self.set(**parameters)
        self._call(self._slave.exitInitializationMode)

    def _receive_log(self, status: int, text: str):
        self.messages.append((status, text))
        if self._logger is not None:
            self._logger(status, text)

    # --- variables ------------------------------------------------------------------
    def vr(self, name: str) -> int:
        return self.variables[name].valueReference

    def kind(self, name: str) -> str:
        """The variable's kind in FMI 2.0's words, for both versions: "Real", "Integer", "Enumeration",
        "Boolean" or "String"."""
        return KINDS[self.variables[name].type]

    def set(self, **values):
        """Set variables by name; dotted FMI names are passed as ``**{"sphere.E": 2e11}``, an Enumeration
        by its item's name or code (``**{"plate.material": "al_6061"}``). A value the FMU refuses raises
        FmiStatusError (status 3, Error, and the FMU's message): the FMU keeps the previous values of the
        call's variables of that type."""
        names = sorted(values, key=lambda n: _KIND_ORDER.index(self.kind(n)))
        converted = []
        for name in names:
            value, kind = values[name], self.kind(name)
            if kind == "Enumeration" and isinstance(value, str):
                value = self.item_code(name, value)
            converted.append(float(value) if kind == "Real" else bool(value) if kind == "Boolean" else int(value))
        key = tuple(names)
        if key not in self._writers:
            self._writers[key] = self.writer(*names)
        self._writers[key](converted)

    def item_code(self, name: str, item: str) -> int:
        """The code of the item ``item`` of the Enumeration variable ``name`` (ValueError listing the items)."""
        items = {i.name: int(i.value) for i in self.variables[name].declaredType.items}
        if item not in items:
            raise ValueError(f"{name} = {item!r} is not one of its items: {', '.join(items)}")
        return items[item]

    def _error(self, exc) -> "FmiStatusError":
        return FmiStatusError(f"{exc}; FMU log: {self.last_message()}", exc.status)

    def _call(self, function, *args):
        """An fmpy call; a status above Warning becomes FmiStatusError with the FMU's last message."""
        try:
            return function(*args)
        except Exception as exc:  # fmpy raises on any status above Warning
            if getattr(exc, "status", None) is None or isinstance(exc, FmiStatusError):
                raise
            raise self._error(exc) from exc

    def get(self, *names):
        """Values of the named variables, in order (Reals as float, Booleans as bool)."""
        if names not in self._readers:
            self._readers[names] = self.reader(*names)
        return self._readers[names]()

    def get_reals(self, names) -> list[float]:
        """Several Reals in one get call (the fast path for hot loops)."""
        return self.get(*names)

    def _access(self, direction: str, names):
        """[(raw fmpy function, its arguments, the values array, the positions in ``names``, kind)] per
        variable type, the arrays allocated once."""
        from ctypes import c_uint32

        module = self._fmi.module()
        groups: dict = {}
        for i, name in enumerate(names):
            suffix, ctype = self._fmi.types[self.variables[name].type]
            groups.setdefault((suffix, ctype), []).append(i)
        out = []
        for (suffix, ctype), positions in groups.items():
            n = len(positions)
            vrs = (c_uint32 * n)(*(self.vr(names[i]) for i in positions))
            values = (getattr(module, ctype) * n)()
            args = (self._slave.component, vrs, n, values, n) if self._fmi.counted else \
                (self._slave.component, vrs, n, values)
            function = getattr(self._slave, f"{self._fmi.prefix}{direction}{suffix}")
            out.append((function, args, values, positions, suffix))
        return out

    def reader(self, *names):
        """A function of no arguments that returns the named variables' values, in order, by one FMI get
        call per variable type (Reals as float, Integers and Enumerations as int, Booleans as bool);
        FmiStatusError on a status above Warning."""
        parts = self._access("Get", names)
        call_error = _fmi_call_exception()
        if len(parts) == 1 and parts[0][4] != "Boolean":  # the hot path: one type, no conversion
            function, args, values, _positions, _suffix = parts[0]

            def read():
                try:
                    function(*args)
                except call_error as exc:
                    raise self._error(exc) from exc
                return values[:]
            return read

        def read_mixed():
            result = [None] * len(names)
            for function, args, values, positions, suffix in parts:
                try:
                    function(*args)
                except call_error as exc:
                    raise self._error(exc) from exc
                for i, value in zip(positions, values):
                    result[i] = bool(value) if suffix == "Boolean" else value
            return result
        return read_mixed

    def writer(self, *names):
        """A function that sets the named variables to a sequence of values, in order, by one FMI set
        call per variable type (values of the variable's type: float, int, bool); FmiStatusError on a
        status above Warning (the FMU keeps the previous values of that call's variables)."""
        parts = self._access("Set", names)
        call_error = _fmi_call_exception()
        if len(parts) == 1:
            function, args, values, _positions, _suffix = parts[0]

            def write(new):
                values[:] = new
                try:
                    function(*args)
                except call_error as exc:
                    raise self._error(exc) from exc
            return write

        def write_mixed(new):
            for function, args, values, positions, _suffix in parts:
                values[:] = [new[i] for i in positions]
                try:
                    function(*args)
                except call_error as exc:
                    raise self._error(exc) from exc
        return write_mixed

    # --- stepping ---------------------------------------------------------------------
    def do_step(self, current_time: float | None = None, step_size: float = 0.0):
        """One communication step; raises FmiStatusError on Discard/Error (the FMU's log says why)."""
        t = self.time if current_time is None else current_time
        try:
            self._step(t, step_size, self._held_states == 0)
        except _fmi_call_exception() as exc:
            raise self._error(exc) from exc
        self.time = t + step_size

    def last_message(self) -> str:
        return self.messages[-1][1] if self.messages else ""

    def reset(self, parameters: dict | None = None, start_time: float = 0.0):
        """Reset the instance and initialise it again at ``start_time`` with ``parameters`` set in
        initialization mode (FmiStatusError if one is refused: the instance is then still in
        initialization mode, and another reset brings it back)."""
        self._call(self._slave.reset)
        self._initialize(start_time, parameters)

    # --- FMU states -------------------------------------------------------------------
    def get_state(self):
        """The FMU's state (fmi2GetFMUstate / fmi3GetFMUState); free it with :meth:`free_state`."""
        state = self._call(getattr(self._slave, self._fmi.state[0]))
        self._held_states += 1
        return state

    def set_state(self, state):
        """Restore a state of this FMU (from :meth:`get_state` or :meth:`deserialize_state`)."""
        self._call(getattr(self._slave, self._fmi.state[1]), state)

    def free_state(self, state):
        self._call(getattr(self._slave, self._fmi.state[2]), state)
        self._held_states = max(self._held_states - 1, 0)

    def serialize_state(self, state) -> bytes:
        return self._call(getattr(self._slave, self._fmi.state[3]), state)

    def deserialize_state(self, data: bytes):
        """A state from :meth:`serialize_state`'s bytes (of this FMU or of its other implementations, FMI
        versions included: one core, one state format); free it with :meth:`free_state`."""
        state = self._call(getattr(self._slave, self._fmi.state[4]), data)
        self._held_states += 1
        return state

    @property
    def slave(self):
        """The underlying fmpy slave (``FMU2Slave`` or ``FMU3Slave``, by :attr:`fmi_version`) for raw calls."""
        return self._slave

    def close(self):
        if self._slave is None:
            return
        try:
            self._slave.terminate()
        finally:
            self._slave.freeInstance()
            self._slave = None
            self._readers.clear()
            self._writers.clear()
            _LOG_ROUTES.pop(self.instance_name, None)
            if self._own_dir:
                shutil.rmtree(self.unzip_dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _fmi_call_exception():
    from fmpy.fmi1 import FMICallException

    return FMICallException
