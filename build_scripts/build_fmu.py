"""Build the project's FMUs with pythonfmu, complete their modelDescription.xml and validate them.

    python build_scripts/build_fmu.py [--out DIR]

builds DIR/SpherePlateImpact.fmu (default DIR: dist/), bundling the ``restitution``
package from fmu_src/ (the same source ``pip install`` installs), then:

* rewrites modelDescription.xml with what pythonfmu cannot write (FMI-NOTES.md): units
  and UnitDefinitions, descriptions, min/max, and a ModelStructure that declares each
  output's direct dependence on the input (direct feedthrough) and the InitialUnknowns;
  value references, names and types are left as pythonfmu wrote them, since the binary
  never reads the XML;
* makes the Linux binary loadable by plain C hosts (``native_host.make_standalone``);
* checks the result with fmpy's validation and fails on any problem.
"""
from __future__ import annotations

import argparse
import importlib
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

ROOT = Path(__file__).resolve().parent.parent
FMU_SRC = ROOT / "fmu_src"
PACKAGE = FMU_SRC / "restitution"

#: FMU model identifier -> slave script in fmu_src/.
FMUS = {"SpherePlateImpact": FMU_SRC / "sphere_plate_impact_slave.py",
        "BouncingBall": FMU_SRC / "bouncing_ball_slave.py"}

#: SI base-unit exponents of every unit the FMUs use.
UNITS = {
    "1": {},
    "m": {"m": 1},
    "s": {"s": 1},
    "kg": {"kg": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s2": {"m": 1, "s": -2},
    "Pa": {"kg": 1, "m": -1, "s": -2},
    "kg/m3": {"kg": 1, "m": -3},
}

PARAMETER_CAUSALITIES = ("parameter", "input")


def complete_model_description(xml_text: str, variables, allowed_range, feedthrough=None) -> str:
    """modelDescription.xml with units, descriptions, limits and a full ModelStructure.

    ``variables`` is the slave's table: (name, type, causality, unit, start, description, key);
    ``allowed_range(name)`` gives (check, text, min, max) for inputs and parameters;
    ``feedthrough``: names of the outputs that depend directly on the inputs (default: all
    but V_c, as in SpherePlateImpact).
    """
    spec = {row[0]: row for row in variables}
    root = ET.fromstring(xml_text)
    model_variables = root.find("ModelVariables")
    scalar_variables = list(model_variables)
    index = {sv.get("name"): i + 1 for i, sv in enumerate(scalar_variables)}

    used_units = set()
    for sv in scalar_variables:
        name, vtype, causality, unit, _start, description, _key = spec[sv.get("name")]
        sv.set("description", description)
        type_node = sv[0]
        if vtype == "Real" and unit is not None:
            type_node.set("unit", unit)
            used_units.add(unit)
        if causality in PARAMETER_CAUSALITIES:
            _check, _text, low, high = allowed_range(name)
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

    inputs = [index[row[0]] for row in variables if row[2] == "input"]
    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    outputs = ET.SubElement(structure, "Outputs")
    initial = ET.SubElement(structure, "InitialUnknowns")
    for row in variables:
        if row[2] != "output":
            continue
        if feedthrough is None:
            depends_on_input = row[6] not in ("V_c",)  # V_c depends on parameters only
        else:
            depends_on_input = row[0] in feedthrough
        deps = " ".join(map(str, inputs)) if depends_on_input else ""
        attrs = {"index": str(index[row[0]]), "dependencies": deps}
        if deps:
            attrs["dependenciesKind"] = " ".join("dependent" for _ in inputs)
        ET.SubElement(outputs, "Unknown", attrs)
        ET.SubElement(initial, "Unknown", {"index": str(index[row[0]])})
    for element in root.iter():
        if element.text is not None and not element.text.strip():
            element.text = None
        element.tail = None
    ET.indent(root, "  ")
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _rewrite_zip_member(fmu: Path, member: str, transform) -> None:
    tmp = fmu.with_suffix(".tmp")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == member:
                data = transform(data.decode("utf-8")).encode("utf-8")
            dst.writestr(item, data)
    tmp.replace(fmu)


#: Subfolders of the package the FMUs bundle; the others (cosim/, scene/, sweep/, ...) are
#: host-side helpers whose imports (fmpy, dask, matplotlib, ...) the slaves never need. Bundling
#: them made the plain-C-host loader require those packages at start-up (python_env.txt require=).
BUNDLED_SUBDIRS = {"data"}


def _physics_only(directory, names):
    """copytree filter: no caches, and only BUNDLED_SUBDIRS below the package root."""
    ignored = set(shutil.ignore_patterns("__pycache__", "*.pyc")(directory, names))
    if Path(directory).resolve() == PACKAGE.resolve():
        ignored |= {n for n in names if (PACKAGE / n).is_dir() and n not in BUNDLED_SUBDIRS}
    return ignored


def build_one(model: str, out_dir: Path, standalone: bool = True) -> Path:
    """Build, complete and validate ``out_dir/<model>.fmu``; return its path."""
    from pythonfmu.builder import FmuBuilder
    from fmpy.validation import validate_fmu

    script = FMUS[model]
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fmu_build_") as tmp:
        staged = Path(tmp) / "restitution"
        shutil.copytree(PACKAGE, staged, ignore=_physics_only)
        fmu = FmuBuilder.build_FMU(script, dest=out_dir, project_files=[staged],
                                   canGetAndSetFMUstate=True, canSerializeFMUstate=True)
    sys.path.insert(0, str(script.parent))
    slave_module = importlib.import_module(script.stem)
    _rewrite_zip_member(Path(fmu), "modelDescription.xml",
                        lambda xml: complete_model_description(xml, slave_module.VARIABLES,
                                                                     slave_module.allowed_range,
                                                                     getattr(slave_module, "FEEDTHROUGH", None)))
    if standalone and shutil.which("gcc") is None:
        print("warning: gcc not found; the FMU will need a Python host (fmpy, libcosimpy)", file=sys.stderr)
    elif standalone:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from native_host.make_standalone import make_standalone
        make_standalone(Path(fmu))
    problems = validate_fmu(str(fmu))
    if problems:
        raise SystemExit(f"{fmu} failed fmpy validation:\n" + "\n".join(problems))
    return Path(fmu)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "dist", help="output directory (default: dist/)")
    parser.add_argument("--python-hosts-only", action="store_true",
                        help="skip the plain-C-host loader (the FMU then needs a Python host)")
    args = parser.parse_args(argv)
    for model in FMUS:
        fmu = build_one(model, args.out, standalone=not args.python_hosts_only)
        print(f"built {fmu} (fmpy validation: 0 problems)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
