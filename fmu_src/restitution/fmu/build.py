"""Build the project's FMUs with pythonfmu, complete their modelDescription.xml and validate them.

    python -m restitution.fmu build [--out DIR]      (or: restitution-fmu build, build_scripts/build_fmu.py)

builds DIR/SpherePlateImpact.fmu and DIR/BouncingBall.fmu, bundling the physics modules of
the installed ``restitution`` package (the same source ``pip install`` installs), then:

* rewrites modelDescription.xml with what pythonfmu cannot write (docs/fmi_tools.md): units
  and UnitDefinitions, descriptions, min/max, and a ModelStructure that declares each
  output's direct dependence on the input (direct feedthrough) and the InitialUnknowns;
  value references, names and types are left as pythonfmu wrote them, since the binary
  never reads the XML; and what pythonfmu writes anew in every build: the GUID becomes the
  model's instantiation token (:meth:`restitution.fmu.table.Table.instantiation_token`: a hash
  of the interface table and the version, shared with the native FMUs; pythonfmu's binary does
  not compare GUIDs, the guard does, against this one), ``generationDateAndTime`` comes from
  SOURCE_DATE_EPOCH or is left out, so two builds of the same sources write the same file;
* records a hash of the sources it was built from (``resources/build_info.json``), which
  :func:`default_fmu` compares to decide whether an FMU is stale;
* puts the guard in front of pythonfmu's Linux binary (``build_guard.make_standalone``: the C FMI
  front checks every call against the FMI 2.0 state machine and the interface table generated
  from the model's interface table, and the binary also loads in plain C hosts; needs gcc, without it
  the FMU is built for Python hosts only, unguarded, and the build says so);
* checks the result with fmpy's validation.

Everything is built in a temporary directory beside the output and moved into place
(``os.replace``) only after validation, so a failed build leaves the previous FMU untouched.
"""
from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from ..about import AUTHOR, COPYRIGHT, LICENSE, VERSION
from .documentation import documentation_files
from .model_description3 import generation_date_and_time
from .models import FOLDERS, SLAVE_SUPPORT, slave_script, table
from .sources import BUILD_INFO, PACKAGE, bundle_filter, recorded_source_hash, source_hash
from .table import UNITS

#: FMU model identifier -> pythonfmu slave script (shipped with the package, in the model's folder).
FMUS = {model: slave_script(model) for model in FOLDERS}


class BuildError(RuntimeError):
    """The FMU cannot be built here (a one-line reason for the user: no pythonfmu, unwritable --out, ...)."""


PARAMETER_CAUSALITIES = ("parameter", "input")


def complete_model_description(xml_text: str, table) -> str:
    """modelDescription.xml with the package's version, author, copyright and license, and units,
    descriptions, limits and a full ModelStructure, from the model's interface ``table`` (:class:`restitution.fmu.table.Table`): each output's dependence on
    the inputs is its ``feedthrough``. The GUID is the table's instantiation token (pythonfmu writes a
    new random one each time) and ``generationDateAndTime`` is SOURCE_DATE_EPOCH's, or absent
    (:func:`restitution.fmu.model_description3.generation_date_and_time`)."""
    root = ET.fromstring(xml_text)
    for attribute, value in (("guid", table.instantiation_token(VERSION)), ("author", AUTHOR), ("version", VERSION),
                             ("copyright", COPYRIGHT), ("license", LICENSE)):
        root.set(attribute, value)
    date = generation_date_and_time()
    if date is None:
        root.attrib.pop("generationDateAndTime", None)
    else:
        root.set("generationDateAndTime", date)
    model_variables = root.find("ModelVariables")
    scalar_variables = list(model_variables)
    index = {sv.get("name"): i + 1 for i, sv in enumerate(scalar_variables)}

    used_units = set()
    for sv in scalar_variables:
        var = table[sv.get("name")]
        sv.set("description", var.description)
        type_node = sv[0]
        if var.enumeration is not None:  # an Integer choice declared as an Enumeration (same get/set calls)
            type_node.tag = "Enumeration"
            type_node.set("declaredType", var.enumeration)
        if var.type == "Real" and var.unit is not None:
            type_node.set("unit", var.unit)
            used_units.add(var.unit)
        if var.derivative is not None:
            type_node.set("derivative", str(index[var.derivative]))
        if var.causality in PARAMETER_CAUSALITIES:
            low, high = var.xml_limits()
            if low is not None:
                type_node.set("min", low)
            if high is not None:
                type_node.set("max", high)

    unit_defs = ET.Element("UnitDefinitions")
    for unit in sorted(used_units):
        node = ET.SubElement(unit_defs, "Unit", name=unit)
        if UNITS[unit]:
            ET.SubElement(node, "BaseUnit", {k: str(v) for k, v in UNITS[unit].items()})
    # FMI 2.0 element order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories, ...
    position = list(root).index(root.find("CoSimulation")) + 1
    root.insert(position, unit_defs)
    if table.enumerations:
        root.insert(position + 1, _type_definitions(table))

    inputs = [index[var.name] for var in table.inputs]
    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    outputs = ET.SubElement(structure, "Outputs")
    derivatives = ET.SubElement(structure, "Derivatives") if table.derivatives else None
    initial = ET.SubElement(structure, "InitialUnknowns")
    for var in table.outputs:
        deps = " ".join(map(str, inputs)) if var.feedthrough else ""
        attrs = {"index": str(index[var.name]), "dependencies": deps}
        if deps:
            attrs["dependenciesKind"] = " ".join("dependent" for _ in inputs)
        ET.SubElement(outputs, "Unknown", attrs)
    for var in table.derivatives:  # may depend on every state, parameter and input (no dependencies given)
        ET.SubElement(derivatives, "Unknown", {"index": str(index[var.name])})
    for var in table.initial_unknowns:
        attrs = {"index": str(index[var.name])}
        if var.initial_dependencies is not None:
            attrs["dependencies"] = " ".join(str(i) for i in sorted(index[name] for name in var.initial_dependencies))
        ET.SubElement(initial, "Unknown", attrs)
    for element in root.iter():
        if element.text is not None and not element.text.strip():
            element.text = None
        element.tail = None
    ET.indent(root, "  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _type_definitions(table) -> ET.Element:
    """<TypeDefinitions> with an Enumeration type for each ``enumeration`` of the table: its items are
    the variable's choices, valued by their codes."""
    node = ET.Element("TypeDefinitions")
    for name, var in table.enumerations.items():
        simple = ET.SubElement(node, "SimpleType", name=name)
        items = ET.SubElement(simple, "Enumeration")
        for (word, code), text in zip(var.codes.items(), var.item_descriptions or [""] * len(var.codes)):
            ET.SubElement(items, "Item", {"name": word, "value": str(code), "description": text})
    return node


def _rewrite_zip(fmu: Path, transform=None, member: str | None = None, extra: dict | None = None) -> None:
    """Rewrite ``member`` of the zip at ``fmu`` through ``transform`` and add the ``extra`` files."""
    tmp = fmu.with_suffix(".tmp")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            if extra and item.filename in extra:
                continue
            data = src.read(item.filename)
            if item.filename == member:
                data = transform(data.decode("utf-8")).encode("utf-8")
            dst.writestr(item, data)
        for name, data in (extra or {}).items():
            dst.writestr(name, data)
    tmp.replace(fmu)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _writable_dir(out_dir: Path) -> Path:
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise BuildError(f"--out {out_dir}: exists and is not a directory")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BuildError(f"--out {out_dir}: cannot create the directory ({exc.strerror})") from None
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise BuildError(f"--out {out_dir}: directory is not writable")
    return out_dir


def _require_build_tools():
    try:
        from pythonfmu.builder import FmuBuilder
        from fmpy.validation import validate_fmu
    except ImportError as exc:
        raise BuildError(f"building an FMU needs pythonfmu and fmpy ({exc.name} is missing): "
                         "pip install 'restitution[fmu]'") from None
    return FmuBuilder, validate_fmu


def build_one(model: str, out_dir: Path, standalone: bool = True, log=None) -> Path:
    """Build, complete and validate ``out_dir/<model>.fmu``; return its path.

    The FMU is built and validated in a temporary directory inside ``out_dir`` and moved into
    place only then, readable as the umask allows (0644 typically). ``log(message)`` receives
    warnings (default: stderr).
    """
    if log is None:
        def log(message):
            print(message, file=sys.stderr)
    FmuBuilder, validate_fmu = _require_build_tools()
    try:
        generation_date_and_time()  # a malformed SOURCE_DATE_EPOCH stops the build before anything is built
    except ValueError as exc:
        raise BuildError(str(exc)) from None
    script = FMUS[model]
    out_dir = _writable_dir(out_dir)
    with tempfile.TemporaryDirectory(prefix=f".{model}-build-", dir=out_dir) as tmp:
        staged = Path(tmp) / "stage" / "restitution"
        shutil.copytree(PACKAGE, staged, ignore=bundle_filter)
        if str(SLAVE_SUPPORT.parent) not in sys.path:  # pythonfmu imports the slave, which imports it by name
            sys.path.append(str(SLAVE_SUPPORT.parent))
        fmu = Path(FmuBuilder.build_FMU(script, dest=tmp, project_files=[staged, SLAVE_SUPPORT],
                                        canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        info = json.dumps({"model": model, "source_hash": source_hash(model)}, indent=1)
        _rewrite_zip(fmu, lambda xml: complete_model_description(xml, table(model)),
                     member="modelDescription.xml", extra={BUILD_INFO: info, **documentation_files(model, "2.0")})
        if standalone and shutil.which("gcc") is None:
            log(f"warning: gcc not found: {model}.fmu is built for Python hosts only (fmpy, libcosimpy), "
                "without the C guard that checks every FMI call; install gcc")
        elif standalone:
            from .build_guard import make_standalone
            from .interface import c_header
            make_standalone(fmu, interface_header=c_header(model))
        problems = validate_fmu(str(fmu))
        if problems:
            raise BuildError(f"{model}.fmu failed fmpy validation: " + "; ".join(problems))
        os.chmod(fmu, 0o666 & ~_umask())
        target = out_dir / f"{model}.fmu"
        os.replace(fmu, target)
    return target


def build_all(out_dir: Path, standalone: bool = True, log=None) -> list[Path]:
    """Build every FMU of the project into ``out_dir``, then their native twins into ``out_dir/native``."""
    built = [build_one(model, out_dir, standalone=standalone, log=log) for model in FMUS]
    from .build_native import build_native  # skipped with a message where they cannot be built
    return built + build_native(out_dir, log=log)


def _checkout_dist() -> Path | None:
    """dist/ of the source checkout this package runs from (editable install), else None."""
    root = PACKAGE.parent.parent
    if (root / "pyproject.toml").is_file() and (root / "fmu_src" / "restitution").resolve() == PACKAGE:
        return root / "dist"
    return None


def default_fmu_dir() -> Path:
    """Where :func:`default_fmu` keeps the FMUs: dist/ in a source checkout, else a per-user cache."""
    dist = _checkout_dist()
    if dist is not None:
        return dist
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return cache / "restitution" / "fmus"


def default_fmu(out_dir: str | Path | None = None, model: str = "SpherePlateImpact",
                rebuild: bool = False, log=None) -> Path:
    """Path of ``<model>.fmu`` (default SpherePlateImpact) in ``out_dir`` (default :func:`default_fmu_dir`).

    The FMUs are (re)built when missing, built from other sources than the installed package's
    (the source hash recorded in the FMU differs; a stale build would run old code), or when
    ``rebuild``. ``log(message)`` is told when a build starts. Raises :class:`BuildError` with a
    one-line reason naming ``--fmu PATH`` when no FMU can be built here.
    """
    out = Path(out_dir) if out_dir is not None else default_fmu_dir()
    fmu = out / f"{model}.fmu"
    if rebuild or recorded_source_hash(fmu) != source_hash(model):
        if log is not None:
            log(f"building {fmu} ...")
        try:
            build_all(out, log=log)
        except BuildError as exc:
            raise BuildError(f"no usable {fmu.name} at {out} and it cannot be built here ({exc}); "
                             f"pass --fmu PATH to use an existing one") from None
    return fmu
