"""What the project's pythonfmu slaves share: setters that refuse bad values and FMU states that
carry a schema and are validated before they are restored.

Shipped beside each slave script in the FMU's resources/ (a module name of its own: two pythonfmu
FMUs in one process share sys.modules). Nothing here may raise into pythonfmu, which would turn
any exception into fmi2Fatal: a refusal is logged with fmi2Error and changes nothing.

In the built FMUs the C guard checks every value and keeps the FMU states itself, so these checks
are a second line: they hold for pythonfmu's own binaries (win64), which have no guard, and for
code that drives a slave directly.
"""
from __future__ import annotations

import json

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
