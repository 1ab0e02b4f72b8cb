"""What a scene run gives: per drop its impacts (:class:`DropResult`), per scene the drops and
what they used (:class:`SceneResult`: the printed summary with the bounce table, the warnings, the
CSVs), and the per-impact CSV written drop by drop (:class:`DropWriter`)."""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..cosim.bouncing import Trajectory
from ..fmu.models.sphere_plate_impact.variables import TABLE
from ..output_files import GrowingOutput, atomic_write
from ..assumptions import meaning_lines
from .explain import explain
from .loader import MAX_BOUNCES, Drop, Scene

__all__ = ["DropResult", "SceneResult", "DropWriter", "COLUMNS", "READ_OUTPUTS", "VALIDITY", "apex_heights"]


def _fmu_outputs(*names):
    """(FMU output names, result column names, units) of the outputs ``names``, from the interface table."""
    rows = [TABLE[name] for name in names]
    return names, tuple(v.key for v in rows), tuple(v.unit for v in rows)


#: requested output -> (FMU output names, result column names, units)
READ_OUTPUTS = {
    "bounce_heights": ((), ("apex",), ("m",)),  # from the impact speeds (host side), not an FMU output
    "cor": _fmu_outputs("e", "jgm.e", "zener.e"),
    "contact_durations": _fmu_outputs("zener.t_contact"),
}
#: column -> CSV header
COLUMNS = {"apex": "apex_m", "e": "e", "e_ep": "e_ep", "e_ze": "e_ze", "t_contact": "t_contact_s"}
#: Validity flags read at every impact (FMU Boolean outputs, also the CSV headers): inside
#: JGM's V* <= 1000 and Zener's lambda <= 1.5, and both.
VALIDITY = ("valid", "jgm.in_range", "zener.in_range")
READ_FLAGS = ("effects.plasticity", "effects.plate_waves", *VALIDITY)


def apex_heights(v_rebound, gravity: float) -> np.ndarray:
    """Height reached after each impact [m] from the rebound speeds [m/s]: v^2 / (2 g), 0 where the
    ball does not leave the plate (v_rebound <= 0)."""
    v = np.asarray(v_rebound, dtype=float)
    return np.where(v > 0.0, v * v / (2.0 * gravity), 0.0)


@dataclass
class DropResult(Trajectory):
    """Every impact of one drop; arrays indexed by impact number."""

    drop: Drop
    time: np.ndarray  #: impact instants [s]
    v_approach: np.ndarray  #: [m/s]
    v_rebound: np.ndarray  #: [m/s]
    columns: dict  #: requested columns (apex, e, e_ep, e_ze, t_contact) -> arrays
    plasticity: np.ndarray  #: effects.plasticity at each impact
    plate_waves: np.ndarray  #: effects.plate_waves at each impact
    stop_reason: str  #: "v_min", "e<=0" or "max_bounces"
    gravity: float = 9.80665  #: [m/s2]
    validity: dict = field(default_factory=dict)  #: VALIDITY flag -> Boolean array, per impact
    #: what the FMU said about this drop's impacts outside the validated domain (restitution.assumptions:
    #: once per condition; the runner resets the FMU for each drop)
    departures: list = field(default_factory=list)

    @property
    def out_of_range(self) -> int:
        """Impacts outside the models' validated ranges (``valid`` false)."""
        valid = self.validity.get("valid")
        return 0 if valid is None else int(np.count_nonzero(~valid))

    @property
    def e_negative(self) -> int:
        """Impacts with e < 0 (the FMU's ``e_negative``: a rebound speed below 0, the sphere moving on with
        the plate; the drop ends at the first)."""
        return int(np.count_nonzero(self.v_rebound < 0.0))

    @property
    def apex(self) -> np.ndarray:
        """Height the ball reaches after each impact [m] (0 where it does not leave the plate)."""
        return apex_heights(self.v_rebound, self.gravity)

    @property
    def cor(self) -> np.ndarray:
        """The COR applied at each impact, rebound over approach speed [1] (the FMU's e)."""
        return self.v_rebound / self.v_approach

    @property
    def at_rest(self) -> bool:
        """False when the drop stopped at its bounce limit with the ball still bouncing."""
        return self.stop_reason != "max_bounces"

    @property
    def rest_time(self) -> float:
        return float(self.time[-1]) if self.time.size else 0.0

    @property
    def drop_height(self) -> float:
        """[m]"""
        return self.drop.drop_height


@dataclass
class SceneResult:
    scene: Scene
    drops: list  #: DropResult per drop, in scene order
    plasticity_mode: str
    plate_waves_mode: str
    zener_method: str
    wall_time: float  #: seconds spent simulating the drops (FMU instantiation excluded)
    fmu_path: Path | None = None
    notes: list = field(default_factory=list)

    @property
    def n_impacts(self) -> int:
        return sum(d.n_impacts for d in self.drops)

    def effect_counts(self) -> dict:
        """Impacts in total and where each effect was active."""
        return {"impacts": self.n_impacts,
                "plasticity": int(sum(d.plasticity.sum() for d in self.drops)),
                "plate_waves": int(sum(d.plate_waves.sum() for d in self.drops))}

    def columns(self) -> list:
        return [c for out in self.scene.outputs for c in READ_OUTPUTS[out][1]]

    @property
    def out_of_range(self) -> int:
        """Impacts outside the models' validated ranges (``valid`` false), over every drop."""
        return sum(d.out_of_range for d in self.drops)

    @property
    def e_negative(self) -> int:
        """Impacts with e < 0 (``e_negative``), over every drop."""
        return sum(d.e_negative for d in self.drops)

    def not_at_rest(self) -> list:
        """The drops that stopped at ``simulation.max_bounces`` with the ball still bouncing."""
        return [d for d in self.drops if not d.at_rest]

    def rest_warning(self) -> str | None:
        """What to do when some drops did not come to rest within their bounce limit, else None."""
        stuck = self.not_at_rest()
        if not stuck:
            return None
        sim = self.scene.simulation
        first = stuck[0]
        why = (" With e this close to 1 the model loses almost no energy per impact (little plastic deformation "
               "and almost none into the plate's waves), so the ball would bounce for a long time."
               if first.cor[-1] > 0.99 else "")
        return (f"warning: {len(stuck)} of {len(self.drops)} drops did not come to rest within "
                f"simulation.max_bounces = {sim.max_bounces} impacts (first: {first.drop.label}, last e = "
                f"{first.cor[-1]:.6g}, last rebound {first.v_rebound[-1]:.3g} m/s > v_min = {sim.v_min:g} m/s); "
                f"their rows end at the bounce limit.{why} Raise simulation.max_bounces (at most {MAX_BOUNCES}) "
                f"or simulation.v_min")

    def warning(self) -> str | None:
        """One line when any impact lies outside the validated ranges, else None."""
        n = self.out_of_range
        if not n:
            return None
        jgm = sum(int(np.count_nonzero(~d.validity["jgm.in_range"])) for d in self.drops)
        zener = sum(int(np.count_nonzero(~d.validity["zener.in_range"])) for d in self.drops)
        return (f"warning: {n} of {self.n_impacts} impacts lie outside the models' validated ranges "
                f"(valid = 0: {jgm} with V* > 1000, {zener} with lambda > 1.5); their e is an extrapolation")

    def departure_warnings(self) -> list[str]:
        """One line per condition of :mod:`restitution.assumptions` that any impact met, in the FMU's
        words (quantity, value, limit), naming the first drop that met it (the FMU says it once per drop:
        the runner resets it for each)."""
        first = {}
        for d in self.drops:
            for text in d.departures:
                first.setdefault(text.split(" = ", 1)[0], f"warning: {d.drop.label}: {text}")
        return list(first.values())

    def write_csv(self, path) -> Path:
        """One row per impact: drop, impact instant and speed, requested outputs, effects used,
        validity flags (:class:`DropWriter`)."""
        with DropWriter(path, self.scene) as writer:
            for d in self.drops:
                writer.write(d)
        return Path(path)

    def write_summary_csv(self, path) -> Path:
        """One row per drop; written under a temporary name, fsynced and renamed when whole
        (:func:`restitution.output_files.atomic_write`)."""
        rows = [["ball", "plate", "drop_height_m", "impacts", "rest_time_s", "stop_reason",
                 "plasticity_impacts", "plate_wave_impacts", "out_of_range_impacts", "e_negative_impacts"]]
        rows += [[d.drop.ball.name, d.drop.plate.name, f"{d.drop.drop_height:.9g}", d.n_impacts, f"{d.rest_time:.9g}",
                  d.stop_reason, int(d.plasticity.sum()), int(d.plate_waves.sum()), d.out_of_range, d.e_negative]
                 for d in self.drops]
        text = _csv_text(rows)
        return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8", newline=""), "summary CSV")

    def summary(self) -> str:
        """Text table of the drops and of what was left out and why."""
        lines = [f"{self.scene.name}: {len(self.drops)} drops, {self.n_impacts} impacts, "
                 f"{self.wall_time:.3f} s (zener_method = {self.zener_method}, plasticity = {self.plasticity_mode}, "
                 f"plate_waves = {self.plate_waves_mode})"]
        width = max([len(d.drop.label) for d in self.drops] + [4])
        lines.append(f"  {'drop':<{width}}  impacts  plasticity  plate waves  out of range  stop")
        for d in self.drops:
            lines.append(f"  {d.drop.label:<{width}}  {d.n_impacts:7d}  {int(d.plasticity.sum()):10d}  "
                         f"{int(d.plate_waves.sum()):11d}  {d.out_of_range:12d}  {d.stop_reason}")
        said = meaning_lines(self.e_negative, self.out_of_range, self.n_impacts, zero_negative=False)
        lines += [f"  out of range: {said[-1]}"]  # the column's meaning, beside it
        if self.e_negative:
            first = next(d for d in self.drops if d.e_negative)
            lines.append(f"  {said[0]}; those drops end there (stop e<=0; first: {first.drop.label})")
        lines += [f"  {line}" for line in explain(self)]
        lines += self._bounce_table()
        return "\n".join(lines)

    def _bounce_table(self, shown: int = 5) -> list:
        """Per drop, the height reached and the COR at its first ``shown`` impacts."""
        width = max([len(d.drop.label) for d in self.drops] + [4])
        n = min(shown, max([d.n_impacts for d in self.drops] + [0]))
        rows = [[f"{h * 1e3:.4g} ({e:.3g})" for h, e in zip(d.apex[:n], d.cor[:n])] for d in self.drops]
        cell = 2 + max([len(c) for row in rows for c in row] + [len(f"impact {n}")])
        lines = ["  bounce height after each impact [mm] (e [1]); every impact is in the CSV",
                 f"  {'drop':<{width}}" + "".join(f"{'impact ' + str(k + 1):>{cell}}" for k in range(n))]
        for d, row in zip(self.drops, rows):
            more = f"  ... {d.n_impacts - n} more" if d.n_impacts > n else ""
            lines.append(f"  {d.drop.label:<{width}}" + "".join(f"{c:>{cell}}" for c in row) + more)
        return lines

    def plot(self, path) -> Path:
        """One panel per requested output (:func:`restitution.scene.plot.plot_scene`)."""
        from .plot import plot_scene

        return plot_scene(self, path)


class DropWriter:
    """The per-impact CSV of a scene, written drop by drop: each finished drop's rows are written at
    once and fsynced before the next drop starts, so an interrupt loses none, and the file under
    ``path`` only ever holds whole drops (:class:`restitution.output_files.GrowingOutput`). It appears
    under ``path`` with the first finished drop; until then, the file that was there stays.

    Leaving the ``with`` block keeps the file (finished drops included, whatever stopped the run),
    except after an I/O error (an ``OSError``, e.g. writing the summary on a full disk): then the file
    that was under ``path`` before is put back, or the new one removed."""

    def __init__(self, path, scene: Scene):
        self.path = Path(path)
        self.cols = [c for out in scene.outputs for c in READ_OUTPUTS[out][1]]
        self.out = GrowingOutput(self.path, _csv_text([["ball", "plate", "drop_height_m", "impact", "time_s",
                                                        "v_approach_m_s", *(COLUMNS[c] for c in self.cols),
                                                        "plasticity", "plate_waves", *VALIDITY]]), "CSV")

    def write(self, d: DropResult) -> None:
        flags = [d.validity.get(name, np.ones(d.n_impacts, bool)) for name in VALIDITY]
        self.out.append(_csv_text(
            [d.drop.ball.name, d.drop.plate.name, f"{d.drop.drop_height:.9g}", i + 1, f"{d.time[i]:.12g}",
             f"{d.v_approach[i]:.12g}", *(f"{d.columns[c][i]:.12g}" for c in self.cols),
             int(d.plasticity[i]), int(d.plate_waves[i]), *(int(f[i]) for f in flags)]
            for i in range(d.n_impacts)))

    def close(self):
        """Keep the file (OutputWriteError if its last fsync or rename fails: the old one is put back)."""
        self.out.commit()

    def discard(self):
        """Put back the file that was under ``path`` (or remove the new one)."""
        self.out.rollback()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is not None and issubclass(exc_type, OSError):
            self.discard()
        else:
            self.close()


def _csv_text(rows) -> str:
    buffer = io.StringIO()
    csv.writer(buffer).writerows(rows)
    return buffer.getvalue()
