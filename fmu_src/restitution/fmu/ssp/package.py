"""The SSP archives of the ball-on-plate system, written by ``restitution fmu build`` into ``dist/ssp/``:

* ``BallOnPlate.ssp``: SSP 1.0 with the native FMI 2.0 FMUs (``<out>/fmi2/``), for the widest import;
* ``BallOnPlate-SSP2.ssp``: SSP 2.0 with the native FMI 3.0 FMUs (``<out>/fmi3/``).

Each holds ``SystemStructure.ssd`` at the root (:mod:`.ssd`), the two FMUs and the SSV parameter sets
(:mod:`.ssv`) in ``resources/``. The archive is reproducible, written as the FMUs are
(:func:`restitution.reproducible.write_zip`: entries in sorted order, the SSD first, each dated
SOURCE_DATE_EPOCH or 1980-01-01 with fixed permissions), so the same FMUs give the same bytes.
"""
from __future__ import annotations

from pathlib import Path

from ...reproducible import write_zip
from .ssd import Component, system_structure
from .ssv import BALL_SET, DEFAULT_SET, ParameterSet, impact_parameter_sets, parameter_set_element, write_parameter_set
from .xml_common import check_version, fmu_variables

__all__ = ["SSP_FILES", "build_ssp", "inline_ssp", "write_ssps", "deterministic_zip", "SSD_ENTRY"]

#: SSP version -> (archive name, folder of the FMUs below the build's output directory).
SSP_FILES = {"1.0": ("BallOnPlate.ssp", "fmi2"), "2.0": ("BallOnPlate-SSP2.ssp", "fmi3")}
SSD_ENTRY = "SystemStructure.ssd"
MODELS = {"ball": "BouncingBall", "impact": "SpherePlateImpact"}


def deterministic_zip(path: Path, entries: list[tuple[str, bytes]]) -> Path:
    """Write ``entries`` (name, content) to the zip ``path`` reproducibly
    (:func:`restitution.reproducible.write_zip`: fixed times, sorted names, fixed permissions), through a
    temporary file renamed into place so that a reader never finds half an archive."""
    tmp = path.with_name(path.name + ".tmp")
    write_zip(tmp, entries)
    tmp.replace(path)
    return path


def _variables(fmus: dict, fmi_version: str | None, version: str) -> dict:
    """{component: {name: fmpy variable}} of ``fmus`` ({component: path}); each FMU must be of
    ``fmi_version`` where given."""
    variables = {}
    for name, fmu in fmus.items():
        if not Path(fmu).is_file():
            raise FileNotFoundError(f"{fmu}: missing, the SSP {version} needs it")
        variables[name] = fmu_variables(fmu)
        found = _fmi_version(fmu)
        if fmi_version is not None and found != fmi_version:
            raise ValueError(f"{fmu} is an FMI {found} FMU: SSP {version} here holds FMI {fmi_version} FMUs")
    return variables


def build_ssp(version: str, fmu_dir: Path, out: Path, impact_set: str = DEFAULT_SET) -> Path:
    """Write the SSP of ``version`` ("1.0" or "2.0") to ``out`` from ``fmu_dir``/BouncingBall.fmu and
    SpherePlateImpact.fmu (FMI 2.0 FMUs for SSP 1.0, FMI 3.0 for SSP 2.0), the impact component bound to
    ``resources/<impact_set>.ssv`` (default: the Real-only set every importer reads, :mod:`.ssv`)."""
    fmi_version, _float = check_version(version)
    fmus = {name: Path(fmu_dir) / f"{model}.fmu" for name, model in MODELS.items()}
    variables = _variables(fmus, fmi_version, version)
    impact_sets = impact_parameter_sets()
    if impact_set not in {pset.name for pset in impact_sets}:
        raise KeyError(f"impact_set = {impact_set!r}: one of {', '.join(p.name for p in impact_sets)}")
    components = [
        Component("ball", f"resources/{MODELS['ball']}.fmu", variables["ball"], (BALL_SET.entry,)),
        Component("impact", f"resources/{MODELS['impact']}.fmu", variables["impact"],
                  (f"resources/{impact_set}.ssv",)),
    ]
    description = (f"BouncingBall and SpherePlateImpact (FMI {fmi_version} co-simulation), the ball's approach "
                   f"speed to the impact model and its COR back; parameter sets in resources/*.ssv")
    entries = [(SSD_ENTRY, system_structure(version, components, description=description))]
    entries += [(f"resources/{MODELS[name]}.fmu", fmus[name].read_bytes()) for name in MODELS]
    sets = [("ball", BALL_SET)] + [("impact", pset) for pset in impact_sets]
    entries += [(pset.entry, write_parameter_set(pset, variables[name], version))
                for name, pset in sets]
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    return deterministic_zip(Path(out), entries)


def inline_ssp(out: Path, fmus: dict, parameters: dict, step: float, set_name: str = "initialValues") -> Path:
    """An SSP 1.0 archive of the pair ``fmus`` ({"ball": path, "impact": path}, FMI 2.0 or 3.0) whose
    parameters ({component: {variable: value}}) sit inline in SystemStructure.ssd as parameter sets all
    named ``set_name`` (ecos applies the sets of the name it is given), Enumerations as Integer codes,
    the communication step ``step`` [s] in the default experiment."""
    variables = _variables(fmus, None, "1.0")
    components = [Component(name, f"resources/{MODELS[name]}.fmu", variables[name],
                            parameter_sets=(parameter_set_element(ParameterSet(set_name, "", parameters[name]),
                                                                  variables[name], "1.0", enumeration_codes=True),))
                  for name in MODELS]
    entries = [(SSD_ENTRY, system_structure("1.0", components, experiment={"step": step}))]
    entries += [(f"resources/{MODELS[name]}.fmu", Path(fmus[name]).read_bytes()) for name in MODELS]
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    return deterministic_zip(Path(out), entries)


def _fmi_version(fmu: Path) -> str:
    from fmpy import read_model_description

    return read_model_description(str(fmu)).fmiVersion


def write_ssps(out_dir: Path, log=None) -> list[Path]:
    """Every SSP whose FMUs ``out_dir`` holds, into ``out_dir/ssp/`` (:data:`SSP_FILES`); an SSP whose
    FMUs are missing (no native build here) is skipped with a line to ``log``."""
    written = []
    for version, (name, folder) in SSP_FILES.items():
        fmu_dir = Path(out_dir) / folder
        if not all((fmu_dir / f"{m}.fmu").is_file() for m in MODELS.values()):
            if log is not None:
                log(f"warning: {name} (SSP {version}) not written: no {folder}/ FMUs")
            continue
        written.append(build_ssp(version, fmu_dir, Path(out_dir) / "ssp" / name))
    return written
