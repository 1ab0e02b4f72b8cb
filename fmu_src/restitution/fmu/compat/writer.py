"""``restitution fmu compat --out DIR``: the compatibility information of the FMI standard's tools page
(the FMI Cross-Check's format) for each native FMU, model x FMI version x interface:

    DIR/fmus/<2.0|3.0>/<cs|me>/<platform>/restitution/<version>/<Model>/
        <Model>.fmu, <Model>_in.csv, <Model>_ref.csv, <Model>_ref.opt, ReadMe.txt

The CSVs follow the Cross-Check rules: comma separated, numeric cells only, the first column ``time``
increasing, the other names exactly the modelDescription's, at most 10 variables, under 1 MB. The
reference results come from the package (:mod:`.references`), not from the FMU. ``<platform>`` is this
machine's (the FMU holds every platform it was built for).
"""
from __future__ import annotations

import platform as _platform
import shutil
from pathlib import Path

import numpy as np

from ...about import VERSION
from ...output_files import check_outputs
from .references import ball_trajectory, impact_outputs

__all__ = ["EXPERIMENT", "EXPERIMENTS", "write_compat", "platform_folder"]

#: The experiment of every FMU: [s] start, stop, output step (= the co-simulation communication step),
#: and the relative tolerance its reference is reproduced within.
EXPERIMENT = {"StartTime": 0.0, "StopTime": 1.0, "StepSize": 0.01, "RelTol": 1e-4}
#: BouncingBall's drop (its parameters' defaults) and the constant COR of its input.
BALL = {"h0": 0.3, "g": 9.80665, "v_min": 0.1, "e": 0.8}
#: SpherePlateImpact's input: the approach speed ramps linearly from 0.1 to 5 m/s over the experiment.
SPEED_RAMP = (0.1, 5.0)
EXPERIMENTS = {"BouncingBall": "a ball dropped from 0.3 m under 9.80665 m/s2 with a constant COR e = 0.8 "
                               "(its input e, _in.csv), at rest below 0.1 m/s; outputs h and v",
               "SpherePlateImpact": "the FMU's default pair (S2 tool steel, d = 6.35 mm, on Al 6061, t = 6.35 mm) "
                                    "at an approach speed ramping from 0.1 to 5 m/s (_in.csv); outputs e, "
                                    "v_rebound, jgm.e, zener.e"}
INTERFACES = {"cs": "co-simulation", "me": "model exchange"}


def platform_folder(fmi_version: str) -> str:
    """This machine's platform as the Cross-Check names it: FMI 2.0 ``linux64`` and the like, FMI 3.0
    ``x86_64-linux`` and the like."""
    system = {"Linux": "linux", "Darwin": "darwin", "Windows": "win"}[_platform.system()]
    arch = {"AMD64": "x86_64", "arm64": "aarch64"}.get(_platform.machine(), _platform.machine())
    if fmi_version == "2.0":
        return f"{system}64" if arch in ("x86_64", "aarch64") else f"{system}32"
    return f"{arch}-{'windows' if system == 'win' else system}"


def _csv(path: Path, columns: dict) -> None:
    """A Cross-Check CSV: a header of the names, then one row per sample, every cell a number."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    lines = [",".join(names)] + [",".join(repr(float(x)) for x in row) for row in data]
    path.write_text("\n".join(lines) + "\n")


def _reference(model: str, interface: str):
    """(inputs {name: values} at the input times, input times, reference {name: values} at the grid)."""
    start, stop, step = EXPERIMENT["StartTime"], EXPERIMENT["StopTime"], EXPERIMENT["StepSize"]
    grid = start + step * np.arange(int(round((stop - start) / step)) + 1)
    ends = np.array([start, stop])
    if model == "BouncingBall":
        h, v = ball_trajectory(grid, BALL["h0"], BALL["g"], BALL["e"], BALL["v_min"],
                               wait_step=step if interface == "cs" else None)
        return {"e": np.full(2, BALL["e"])}, ends, {"h": h, "v": v}
    speeds = SPEED_RAMP[0] + (SPEED_RAMP[1] - SPEED_RAMP[0]) * (grid - start) / (stop - start)
    if interface == "cs":  # the output at a communication point is that of the input set at the previous one
        speeds = np.concatenate([speeds[:1], speeds[:-1]])
    return {"v_approach": np.array(SPEED_RAMP)}, ends, impact_outputs(speeds)


def _readme(model: str, fmi_version: str, interface: str) -> str:
    return (f"{model}.fmu: FMI {fmi_version} {INTERFACES[interface]}, exported by restitution {VERSION} "
            f"(native C, sources included).\n\n"
            f"Experiment: {EXPERIMENTS[model]}, from {EXPERIMENT['StartTime']} s to {EXPERIMENT['StopTime']} s, "
            f"output step {EXPERIMENT['StepSize']} s"
            + (" (the communication step)" if interface == "cs" else "") + ".\n"
            f"Reference ({model}_ref.csv): computed by the restitution package, not by the FMU"
            + (": the closed-form flights" + (" (the ball waits at the plate for the next communication point, "
                                              "its default contact_mode)" if interface == "cs" else "")
               if model == "BouncingBall" else ": restitution.impact at each sample's speed"
               + (" (co-simulation: the speed set at the previous communication point, the master setting the "
                  "inputs before each step)" if interface == "cs" else "")) + ".\n"
            f"Compare within RelTol = {EXPERIMENT['RelTol']} of each signal's range.\n")


def write_compat(out_dir: Path, fmu_dir: Path, models=("BouncingBall", "SpherePlateImpact")) -> list[Path]:
    """Write the compatibility information of ``fmu_dir``/fmi2 and fmi3 native FMUs into ``out_dir``;
    returns the model folders written. FileNotFoundError naming a missing FMU; OutputPathError where an
    output would overwrite an FMU read (restitution.output_files)."""
    written = []
    for fmi_version, folder in (("2.0", "fmi2"), ("3.0", "fmi3")):
        for model in models:
            fmu = Path(fmu_dir) / folder / f"{model}.fmu"
            if not fmu.is_file():
                raise FileNotFoundError(f"{fmu}: no native FMI {fmi_version} {model}.fmu (run `restitution fmu build`)")
            for interface in INTERFACES:
                target = (Path(out_dir) / "fmus" / fmi_version / interface / platform_folder(fmi_version)
                          / "restitution" / VERSION / model)
                files = {suffix: target / f"{model}{suffix}" for suffix in (".fmu", "_in.csv", "_ref.csv",
                                                                              "_ref.opt")}
                files["ReadMe"] = target / "ReadMe.txt"
                check_outputs({f"--out ({p.name})": p for p in files.values()}, {f"FMU {fmu.name}": fmu})
                target.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(fmu, files[".fmu"])
                inputs, input_times, reference = _reference(model, interface)
                _csv(files["_in.csv"], {"time": input_times, **inputs})
                grid = EXPERIMENT["StartTime"] + EXPERIMENT["StepSize"] * np.arange(len(next(iter(reference.values()))))
                _csv(files["_ref.csv"], {"time": grid, **reference})
                files["_ref.opt"].write_text("".join(f"{k}, {v!r}\n" for k, v in EXPERIMENT.items()))
                files["ReadMe"].write_text(_readme(model, fmi_version, interface))
                written.append(target)
    return written
