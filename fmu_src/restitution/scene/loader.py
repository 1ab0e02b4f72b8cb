"""Scene files: one TOML file per scene, loaded into typed, SI-valued dataclasses.

A scene is a set of plates, balls dropped on them from given heights, the outputs the
user wants, and how exactly they want them. Format (see docs/scenes.md for the full
reference; every key not marked optional is required)::

    [scene]
    name = "Steel ball on a thick steel table"
    description = "..."                       # optional

    [outputs]
    requested = ["bounce_heights", "cor"]     # any of bounce_heights, cor, contact_durations
    tolerance = 1e-2                          # declared: largest allowed difference vs all effects on

    [model]                                   # optional table, defaults shown
    effect_tolerance = 1e-6                   # what plasticity/plate_waves = auto may neglect in e
    zener_method = "exact"                    # exact | paper_fit | linear | ode
    restitution_model = "e45"                 # e45 | e44
    plasticity = "auto"                       # auto | on | off
    plate_waves = "auto"                      # auto | on | off (auto -> on if contact_durations)

    [simulation]                              # optional table, defaults shown
    gravity = "9.80665 m/s2"
    v_min = "0.1 m/s"                         # the ball rests when it rebounds slower than this
    max_bounces = 10000
    master = "closed_form"                    # closed_form | event_mode (FMI 3.0 BouncingBall.fmu, event mode)
    communication_step = "1 ms"               # event_mode: the master's communication step

    [materials.soft_polymer]                  # optional: named custom materials
    E = "10 GPa"
    nu = 0.3
    Sy = "10 MPa"                             # or "brittle" (1e12 Pa, never yields)
    rho = "2000 kg/m3"

    [[plates]]
    name = "table"
    material = "low_carbon_steel"             # a preset, a [materials] name, or an inline table
    thickness = "100 mm"

    [[balls]]
    name = "1/4 in ball"
    material = "chrome_steel"
    diameter = "6.35 mm"
    drop_heights = ["0.2 m", "1 m"]           # one string or a list
    plates = ["table"]                        # optional: default every plate

A dimensional value is a string "<number> <unit>" or a bare number in SI units (as everywhere in
the package); dimensionless values (nu, tolerances) are plain numbers. Materials are preset
names (:data:`restitution.MATERIALS`, or ``table4.<A1..B4>.sphere|plate`` for the paper's
Table 4 cases), a name from ``[materials]``, or an inline table ``{E, nu, Sy, rho}``,
optionally ``{base = "preset", ...}`` overriding some properties of a preset.

Every error is a :class:`SceneError` whose message starts with the file and the key, e.g.
``scene.toml: balls[0].diamter: unknown key (did you mean 'diameter'?)``.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import tomllib  # Python >= 3.11

from ..domain import TYPICAL, outside_text, slipped_prefix
from ..materials import BRITTLE_SY, MATERIALS, TABLE4_CASES, Material, suggest_material, table4_case
from ..model import DOMAIN, EFFECT_MODES, RESTITUTION_MODELS
from ..zener import ZENER_METHODS
from ..units import QUANTITIES, UnitError, parse_quantity, split_quantity

__all__ = ["SceneError", "Scene", "BallSpec", "PlateSpec", "ModelSpec", "SimulationSpec", "Drop",
           "OUTPUTS", "MASTERS", "load_scene", "parse_scene", "resolve_material"]

#: Outputs a scene may request -> what they are.
OUTPUTS = {
    "bounce_heights": "apex height after each impact [m]",
    "cor": "COR components at each impact: e, e_ep (JGM), e_ze (Zener) [1]",
    "contact_durations": "contact duration of each impact [s] (needs Zener's tau0: forces plate_waves = on)",
}


#: What a scene without ``[outputs] requested`` gets: what a user dropping a ball wants to see.
DEFAULT_OUTPUTS = ("bounce_heights", "cor")
#: ``[outputs] tolerance`` when not given: the largest difference ``report`` accepts between the scene as
#: run (effects skipped where ``auto`` allows) and every effect on, relative for heights and contact
#: durations, absolute for CORs. Well above what effect_tolerance = 1e-6 leaves over a drop's bounces.
DEFAULT_TOLERANCE = 1e-3


class SceneError(ValueError):
    """A problem in a scene file; ``key`` is the dotted path of the offending key."""

    def __init__(self, message: str, key: str = "", source: str = ""):
        self.key = key
        self.source = source
        prefix = f"{source}: " if source else ""
        where = f"{key}: " if key else ""
        super().__init__(f"{prefix}{where}{message}")


@dataclass(frozen=True)
class PlateSpec:
    name: str
    material: Material
    thickness: float  #: [m]


@dataclass(frozen=True)
class BallSpec:
    name: str
    material: Material
    diameter: float  #: [m]
    drop_heights: tuple[float, ...]  #: [m]
    plates: tuple[str, ...]  #: names of the plates this ball is dropped on


@dataclass(frozen=True)
class ModelSpec:
    effect_tolerance: float = 1e-6  #: [1] what auto may neglect in e at one impact
    zener_method: str = "exact"
    restitution_model: str = "e45"
    plasticity: str = "auto"
    plate_waves: str = "auto"


#: How a drop is simulated: the runner's own flight in closed form with SpherePlateImpact.fmu at each
#: impact, or the native FMI 3.0 BouncingBall.fmu co-simulated with it in event mode with early return
#: (restitution.cosim.event_mode). Both find each impact at its exact instant.
MASTERS = ("closed_form", "event_mode")


@dataclass(frozen=True)
class SimulationSpec:
    gravity: float = 9.80665  #: [m/s2]
    v_min: float = 0.1  #: [m/s] rest threshold on the rebound speed
    max_bounces: int = 10_000
    master: str = "closed_form"  #: one of MASTERS
    communication_step: float = 1e-3  #: [s] the event-mode master's communication step


@dataclass(frozen=True)
class Drop:
    """One simulation: a ball dropped from a height onto a plate."""

    ball: BallSpec
    plate: PlateSpec
    drop_height: float  #: [m]

    @property
    def label(self) -> str:
        return f"{self.ball.name} on {self.plate.name}, h = {self.drop_height:g} m"

    def package_params(self) -> dict:
        """The ball and the plate as :func:`restitution.impact` keywords [SI units]."""
        return dict(**self.ball.material.params("sphere"), sphere_d=self.ball.diameter,
                    **self.plate.material.params("plate"), plate_t=self.plate.thickness)


@dataclass(frozen=True)
class Scene:
    name: str
    outputs: tuple[str, ...]  #: requested outputs, keys of :data:`OUTPUTS`
    tolerance: float  #: declared largest difference in a requested output vs every effect on
    plates: tuple[PlateSpec, ...]
    balls: tuple[BallSpec, ...]
    model: ModelSpec = field(default_factory=ModelSpec)
    simulation: SimulationSpec = field(default_factory=SimulationSpec)
    description: str = ""
    path: Path | None = None

    def plate(self, name: str) -> PlateSpec:
        return next(p for p in self.plates if p.name == name)

    def drops(self) -> list[Drop]:
        """Every (ball, plate, drop height) of the scene, in file order."""
        return [Drop(ball, self.plate(plate), h) for ball in self.balls for plate in ball.plates
                for h in ball.drop_heights]

    @property
    def stem(self) -> str:
        return self.path.stem if self.path is not None else self.name.lower().replace(" ", "_")

    def effect_modes(self) -> tuple[str, str]:
        """(plasticity, plate_waves) the FMU is run with: the scene's modes, except that
        contact durations need Zener's tau0, so ``plate_waves = auto`` becomes ``on``."""
        waves = self.model.plate_waves
        if waves == "auto" and "contact_durations" in self.outputs:
            waves = "on"
        return self.model.plasticity, waves

    def with_model(self, **changes) -> "Scene":
        return replace(self, model=replace(self.model, **changes))


# --- reading -----------------------------------------------------------------------------

class _Ctx:
    def __init__(self, source: str):
        self.source = source

    def error(self, key: str, message: str) -> SceneError:
        return SceneError(message, key, self.source)


def _join(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def _check_keys(ctx: _Ctx, table: dict, where: str, allowed, required=()):
    if not isinstance(table, dict):
        raise ctx.error(where, f"expected a table, got {table!r}")
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, list(allowed), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ctx.error(_join(where, key), f"unknown key{hint}; allowed here: {', '.join(allowed)}")
    for key in required:
        if key not in table:
            raise ctx.error(_join(where, key), f"missing required key ({allowed[key]})")


def _quantity(ctx, table, where, key, kind, *, positive=True, default=None, domain=None):
    """``domain``: (low, high) [SI] the FMU accepts (:data:`restitution.domain.DOMAIN`), checked here
    so that a value the FMU would reject is a loader error naming the key."""
    full = _join(where, key)
    if key not in table:
        return default
    try:
        value = parse_quantity(full, table[key], kind)
    except UnitError as exc:
        raise SceneError(str(exc), full, ctx.source) from None
    if positive and not value > 0.0:
        raise ctx.error(full, f"{table[key]!r} must be > 0")
    if domain is not None and not domain[0] <= value <= domain[1]:
        unit = QUANTITIES[kind]
        hint = None
        if not isinstance(table[key], str) or _unit_free(table[key]):  # a bare number: SI, maybe a slip
            typical = TYPICAL.get(_TYPICAL_KEY.get(key, key), math.sqrt(domain[0] * domain[1]))
            hint = slipped_prefix(value, unit, lambda x: domain[0] <= x <= domain[1], typical)
        raise ctx.error(full, outside_text(key, value, unit, f"{domain[0]:g} <= value <= {domain[1]:g}", hint))
    return value


#: A scene's key -> the key of :data:`restitution.domain.TYPICAL` whose typical value it has.
_TYPICAL_KEY = {"thickness": "t", "diameter": "d"}


def _unit_free(text: str) -> bool:
    """True for a numeric string without a unit (``"3180"``), which a scene reads as SI."""
    parsed = split_quantity(text)
    return parsed is not None and parsed[1] is None


def _number(ctx, table, where, key, *, low=None, high=None, low_open=False, high_open=False, default=None):
    full = _join(where, key)
    if key not in table:
        return default
    value = table[key]
    if isinstance(value, str):
        raise ctx.error(full, f"{value!r}: expected a plain number (this value is dimensionless, no unit)")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ctx.error(full, f"{value!r}: expected a finite number")
    value = float(value)
    if low is not None and (value <= low if low_open else value < low):
        raise ctx.error(full, f"{value!r} must be {'>' if low_open else '>='} {low:g}")
    if high is not None and (value >= high if high_open else value > high):
        raise ctx.error(full, f"{value!r} must be {'<' if high_open else '<='} {high:g}")
    return value


def _choice(ctx, table, where, key, choices, default):
    full = _join(where, key)
    if key not in table:
        return default
    value = table[key]
    if value not in choices:
        raise ctx.error(full, f"{value!r} is not one of {', '.join(map(repr, choices))}")
    return value


def _string(ctx, table, where, key, default=None):
    full = _join(where, key)
    if key not in table:
        return default
    value = table[key]
    if not isinstance(value, str) or not value.strip():
        raise ctx.error(full, f"{value!r}: expected a non-empty string")
    return value.strip()


def _string_list(ctx, table, where, key):
    value = table[key]
    items = [value] if isinstance(value, str) else value
    if not isinstance(items, list) or not items or not all(isinstance(v, str) for v in items):
        raise ctx.error(_join(where, key), f"{value!r}: expected a string or a non-empty list of strings")
    return items


_MATERIAL_KEYS = {"name": "a label", "base": "a preset to start from", "E": 'elastic modulus, e.g. "69 GPa"',
                  "nu": "Poisson's ratio, 0 <= nu <= 0.5", "Sy": 'yield strength, e.g. "290 MPa", or "brittle"',
                  "rho": 'density, e.g. "2700 kg/m3"', "source": "where the values come from"}


def resolve_material(name: str, custom: dict[str, Material] | None = None) -> Material:
    """A material by name: a scene's own ``[materials]``, a preset, or ``table4.<case>.sphere|plate``.

    Raises KeyError with the known names when there is no such material.
    """
    if custom and name in custom:
        return custom[name]
    if name in MATERIALS:
        return MATERIALS[name]
    parts = name.split(".")
    if len(parts) == 3 and parts[0] == "table4" and parts[1].upper() in TABLE4_CASES and parts[2] in ("sphere", "plate"):
        sphere, plate = table4_case(parts[1])
        return sphere if parts[2] == "sphere" else plate
    known = sorted(set(custom or ()) | set(MATERIALS)) + ["table4.<A1..A4|B1..B4>.<sphere|plate>"]
    raise KeyError(f"unknown material {name!r}; known: {', '.join(known)}")


def _material(ctx, value, where, custom) -> Material:
    if isinstance(value, str):
        try:
            return resolve_material(value, custom)
        except KeyError as exc:
            hint = suggest_material(value, {**MATERIALS, **custom})
            raise ctx.error(where, f"{exc.args[0]}{hint}") from None
    if not isinstance(value, dict):
        raise ctx.error(where, f"{value!r}: expected a material name or a table {{E, nu, Sy, rho}}")
    base = None
    required = ("E", "nu", "Sy", "rho")
    if "base" in value:
        base_name = _string(ctx, value, where, "base")
        try:
            base = resolve_material(base_name, custom)
        except KeyError as exc:
            raise ctx.error(_join(where, "base"), exc.args[0]) from None
        required = ()
    _check_keys(ctx, value, where, _MATERIAL_KEYS, required)
    props = {}
    props["E"] = _quantity(ctx, value, where, "E", "pressure", domain=DOMAIN["sphere_E"])
    props["nu"] = _number(ctx, value, where, "nu", low=0.0, high=0.5)
    if value.get("Sy") == "brittle":
        props["Sy"] = BRITTLE_SY
    else:
        props["Sy"] = _quantity(ctx, value, where, "Sy", "pressure", domain=DOMAIN["sphere_Sy"])
    props["rho"] = _quantity(ctx, value, where, "rho", "density", domain=DOMAIN["sphere_rho"])
    props = {k: v for k, v in props.items() if v is not None}
    label = _string(ctx, value, where, "name", default=None)
    source = _string(ctx, value, where, "source", default=None)
    if base is not None:
        extra = {"name": label or f"{base.name} (modified)", "source": source or f"{base.source}; modified in scene"}
        return replace(base, **props, **extra)
    return Material(label or where, source=source or "scene file", **props)


_TOP = {"scene": "table: name, description", "outputs": "optional table: requested, tolerance",
        "model": "optional table: effect_tolerance, zener_method, restitution_model, plasticity, plate_waves",
        "simulation": "optional table: gravity, v_min, max_bounces, master, communication_step",
        "materials": "optional table of named materials", "plates": "array of tables [[plates]]",
        "balls": "array of tables [[balls]]"}
_SCENE = {"name": "the scene's title", "description": "free text"}
_OUTPUT_KEYS = {"requested": f"a list of {', '.join(OUTPUTS)}",
                "tolerance": "largest allowed difference in a requested output vs every effect on, > 0"}
_MODEL = {"effect_tolerance": "a number >= 0", "zener_method": " | ".join(ZENER_METHODS),
          "restitution_model": " | ".join(RESTITUTION_MODELS), "plasticity": " | ".join(EFFECT_MODES),
          "plate_waves": " | ".join(EFFECT_MODES)}
_SIMULATION = {"gravity": 'an acceleration, e.g. "9.81 m/s2"', "v_min": 'a speed, e.g. "0.1 m/s"',
               "max_bounces": "an integer, 1 ... 100000", "master": " | ".join(MASTERS),
               "communication_step": 'a time, e.g. "1 ms" (master = "event_mode")'}
#: Largest simulation.max_bounces: bounds the time and memory of a drop whose ball never rests.
MAX_BOUNCES = 100_000
_PLATE = {"name": "a unique name", "material": "a material name or table", "thickness": 'a length, e.g. "3.18 mm"'}
_BALL = {"name": "a unique name", "material": "a material name or table", "diameter": 'a length, e.g. "6.35 mm"',
         "drop_heights": 'a length or a list of lengths, e.g. ["0.1 m", "0.5 m"]',
         "plates": "optional: names of plates (default: every plate)"}


def parse_scene(data: dict, source: str = "<scene>", path: Path | None = None) -> Scene:
    """A :class:`Scene` from the parsed TOML ``data`` (``source`` names it in error messages)."""
    ctx = _Ctx(source)
    _check_keys(ctx, data, "", _TOP, ("scene", "plates", "balls"))

    _check_keys(ctx, data["scene"], "scene", _SCENE, ("name",))
    name = _string(ctx, data["scene"], "scene", "name")
    description = _string(ctx, data["scene"], "scene", "description", default="")

    out = data.get("outputs", {})
    _check_keys(ctx, out, "outputs", _OUTPUT_KEYS)
    requested = _string_list(ctx, out, "outputs", "requested") if "requested" in out else list(DEFAULT_OUTPUTS)
    for item in requested:
        if item not in OUTPUTS:
            close = difflib.get_close_matches(item, list(OUTPUTS), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ctx.error("outputs.requested", f"unknown output {item!r}{hint}; one of {', '.join(OUTPUTS)}")
    if len(set(requested)) != len(requested):
        raise ctx.error("outputs.requested", f"{requested!r} lists an output twice")
    tolerance = _number(ctx, out, "outputs", "tolerance", low=0.0, low_open=True, default=DEFAULT_TOLERANCE)

    m = data.get("model", {})
    _check_keys(ctx, m, "model", _MODEL)
    d = ModelSpec()
    model = ModelSpec(
        effect_tolerance=_number(ctx, m, "model", "effect_tolerance", low=0.0, default=d.effect_tolerance),
        zener_method=_choice(ctx, m, "model", "zener_method", ZENER_METHODS, d.zener_method),
        restitution_model=_choice(ctx, m, "model", "restitution_model", RESTITUTION_MODELS, d.restitution_model),
        plasticity=_choice(ctx, m, "model", "plasticity", EFFECT_MODES, d.plasticity),
        plate_waves=_choice(ctx, m, "model", "plate_waves", EFFECT_MODES, d.plate_waves))

    s = data.get("simulation", {})
    _check_keys(ctx, s, "simulation", _SIMULATION)
    d = SimulationSpec()
    max_bounces = s.get("max_bounces", d.max_bounces)
    if isinstance(max_bounces, bool) or not isinstance(max_bounces, int) or not 1 <= max_bounces <= MAX_BOUNCES:
        raise ctx.error("simulation.max_bounces", f"{max_bounces!r}: expected an integer, 1 <= max_bounces <= "
                                                  f"{MAX_BOUNCES} (a ball that never rests stops there)")
    simulation = SimulationSpec(gravity=_quantity(ctx, s, "simulation", "gravity", "acceleration", default=d.gravity),
                                v_min=_quantity(ctx, s, "simulation", "v_min", "speed", default=d.v_min),
                                max_bounces=max_bounces,
                                master=_choice(ctx, s, "simulation", "master", MASTERS, d.master),
                                communication_step=_quantity(ctx, s, "simulation", "communication_step", "time",
                                                             default=d.communication_step))

    custom: dict[str, Material] = {}
    materials = data.get("materials", {})
    if not isinstance(materials, dict):
        raise ctx.error("materials", f"expected a table of named materials, got {materials!r}")
    for key, value in materials.items():
        where = f"materials.{key}"
        if not isinstance(value, dict):
            raise ctx.error(where, f"expected a table {{E, nu, Sy, rho}}, got {value!r}")
        value = dict(value)
        value.setdefault("name", key)
        custom[key] = _material(ctx, value, where, custom)

    plates = []
    for i, p in enumerate(_array(ctx, data, "plates")):
        where = f"plates[{i}]"
        _check_keys(ctx, p, where, _PLATE, ("name", "material", "thickness"))
        plates.append(PlateSpec(name=_string(ctx, p, where, "name"),
                                material=_material(ctx, p["material"], f"{where}.material", custom),
                                thickness=_quantity(ctx, p, where, "thickness", "length",
                                                    domain=DOMAIN["plate_t"])))
    _unique(ctx, plates, "plates")
    plate_names = [p.name for p in plates]

    balls = []
    for i, b in enumerate(_array(ctx, data, "balls")):
        where = f"balls[{i}]"
        _check_keys(ctx, b, where, _BALL, ("name", "material", "diameter", "drop_heights"))
        heights = b["drop_heights"]
        heights = heights if isinstance(heights, list) else [heights]
        if not heights:
            raise ctx.error(f"{where}.drop_heights", "expected at least one drop height")
        # the first impact's speed sqrt(2 g h) must be one the FMU accepts (v_approach <= DOMAIN["v"][1])
        highest = DOMAIN["v"][1] ** 2 / (2.0 * simulation.gravity)
        drop_heights = tuple(_quantity(ctx, {f"drop_heights[{j}]": h}, where, f"drop_heights[{j}]", "length",
                                       domain=(0.0, highest))
                             for j, h in enumerate(heights))
        on = _string_list(ctx, b, where, "plates") if "plates" in b else plate_names
        for plate in on:
            if plate not in plate_names:
                raise ctx.error(f"{where}.plates", f"no plate named {plate!r}; plates: {', '.join(plate_names)}")
        balls.append(BallSpec(name=_string(ctx, b, where, "name"),
                              material=_material(ctx, b["material"], f"{where}.material", custom),
                              diameter=_quantity(ctx, b, where, "diameter", "length", domain=DOMAIN["sphere_d"]),
                              drop_heights=drop_heights, plates=tuple(on)))
    _unique(ctx, balls, "balls")

    return Scene(name=name, description=description, outputs=tuple(requested), tolerance=tolerance,
                 plates=tuple(plates), balls=tuple(balls), model=model, simulation=simulation, path=path)


def _array(ctx, data, key):
    items = data[key]
    if not isinstance(items, list) or not items or not all(isinstance(x, dict) for x in items):
        raise ctx.error(key, f"expected at least one [[{key}]] table")
    return items


def _unique(ctx, items, key):
    seen = set()
    for i, item in enumerate(items):
        if item.name in seen:
            raise ctx.error(f"{key}[{i}].name", f"{item.name!r} is used twice")
        seen.add(item.name)


def load_scene(path) -> Scene:
    """Read and check a scene file; :class:`SceneError` names the file and the key on any problem."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(f"cannot read the scene file: {exc.strerror or exc}", source=str(path)) from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"not UTF-8 text (byte {exc.start}): a scene file is TOML, UTF-8 encoded",
                         source=str(path)) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"not valid TOML: {exc}", source=str(path)) from None
    return parse_scene(data, source=str(path), path=path)
