"""Build the pythonfmu FMUs, ``DIR/<model>.fmu``: the model's Python physics run by pythonfmu's binary,
behind the C guard.

For each model: pythonfmu builds the FMU from the model's slave script, bundling the physics modules of
the installed ``restitution`` package (the same source ``pip install`` installs); then

* its modelDescription.xml is *replaced* by the one :func:`restitution.fmu.describe.fmi2.model_description`
  writes from the model's interface table (units, descriptions, ranges, enumerations, a full
  ModelStructure, the table's instantiation token as GUID), after checking that the variables pythonfmu
  registered are the table's, in its order (pythonfmu's binary numbers them by registration; it never
  reads the XML nor compares GUIDs: the guard does, against this one);
* ``resources/build_info.json`` records a hash of the sources it was built from, which
  :func:`restitution.fmu.builders.products.default_fmu` compares to decide whether an FMU is stale;
  ``documentation/`` gets the index page and the licenses;
* the guard goes in front of pythonfmu's Linux binary (:func:`restitution.fmu.builders.guard.add_guard`:
  the C FMI front checks every call against the FMI 2.0 state machine and the model's interface table,
  and the binary also loads in plain C hosts; needs gcc, without it the FMU is built for Python hosts
  only, unguarded, and the build says so);
* fmpy's validation checks the result.

Everything is built in a temporary directory beside the output and moved into place only after
validation, so a failed build leaves the previous FMU untouched.
"""
from __future__ import annotations

import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from ..describe import fmi2
from ..describe.c_header import c_header
from ..describe.common import generation_date_and_time
from ..models import SLAVE_SUPPORT, table
from .files import BuildError, place, rewrite_zip, writable_dir
from .licenses import documentation_files
from .sources import BUILD_INFO, FMUS, PACKAGE, PYTHONFMU_FOLDERS, bundle_filter, source_hash
from .toolchains import pythonfmu_label

__all__ = ["FMUS", "build_one", "registered_variables"]


def _require_build_tools():
    try:
        from pythonfmu.builder import FmuBuilder
        from fmpy.validation import validate_fmu
    except ImportError as exc:
        raise BuildError(f"building an FMU needs pythonfmu and fmpy ({exc.name} is missing): "
                         "pip install 'restitution[fmu]'") from None
    return FmuBuilder, validate_fmu


def registered_variables(xml_text: str) -> list[tuple[str, int, str, str]]:
    """(name, value reference, type, causality) of every variable a pythonfmu-written modelDescription
    declares, in its order: what the slave registered."""
    return [(sv.get("name"), int(sv.get("valueReference")), sv[0].tag, sv.get("causality", "local"))
            for sv in ET.fromstring(xml_text).find("ModelVariables")]


def _check_registration(model: str, xml_text: str) -> None:
    """BuildError unless the slave registered exactly the table's variables, in its order, with its value
    references, types and causalities (the binary numbers variables by registration, the description
    that replaces pythonfmu's by the table)."""
    expected = [(row.name, row.vr, row.type, row.causality) for row in table(model)]
    found = [(name, vr, "Integer" if vtype == "Enumeration" else vtype, causality)
             for name, vr, vtype, causality in registered_variables(xml_text)]
    if found != expected:
        first = next((i for i, (a, b) in enumerate(zip(found, expected)) if a != b), min(len(found), len(expected)))
        raise BuildError(f"{model}: the slave registers its variables unlike the interface table "
                         f"(first difference at position {first}: slave {found[first:first + 1]}, "
                         f"table {expected[first:first + 1]})")


def _guard_compiler_found() -> bool:
    from .toolchains import ToolchainMissing, compiler

    try:
        compiler("x86_64-linux")
    except ToolchainMissing:
        return False
    return True


def build_one(model: str, out_dir: Path, guard: bool = True, log=None, progress=None) -> Path:
    """Build, complete and validate ``out_dir/<model>.fmu``; return its path.

    The FMU is built and validated in a temporary directory inside ``out_dir`` and moved into
    place only then, readable as the umask allows (0644 typically). ``log(message)`` receives
    warnings (default: stderr); ``progress`` (a :class:`~restitution.fmu.builders.progress.Progress`),
    a start and an end line (default: none).
    """
    from .progress import quiet

    if log is None:
        def log(message):
            print(message, file=sys.stderr, flush=True)
    FmuBuilder, validate_fmu = _require_build_tools()
    try:
        generation_date_and_time()  # a malformed SOURCE_DATE_EPOCH stops the build before anything is built
    except ValueError as exc:
        raise BuildError(str(exc)) from None
    out_dir = writable_dir(out_dir)
    with (progress or quiet()).step(f"{model}.fmu", ", ".join(PYTHONFMU_FOLDERS), pythonfmu_label(guard)):
        return _build(model, out_dir, guard, log, FmuBuilder, validate_fmu)


def _build(model: str, out_dir: Path, guard: bool, log, FmuBuilder, validate_fmu) -> Path:
    """:func:`build_one`'s work, its checks done."""
    script = FMUS[model]
    with tempfile.TemporaryDirectory(prefix=f".{model}-build-", dir=out_dir) as tmp:
        staged = Path(tmp) / "stage" / "restitution"
        shutil.copytree(PACKAGE, staged, ignore=bundle_filter)
        if str(SLAVE_SUPPORT.parent) not in sys.path:  # pythonfmu imports the slave, which imports it by name
            sys.path.append(str(SLAVE_SUPPORT.parent))
        fmu = Path(FmuBuilder.build_FMU(script, dest=tmp, project_files=[staged, SLAVE_SUPPORT],
                                        canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        with zipfile.ZipFile(fmu) as archive:
            _check_registration(model, archive.read("modelDescription.xml").decode("utf-8"))
        info = json.dumps({"model": model, "source_hash": source_hash(model)}, indent=1)
        rewrite_zip(fmu, {"modelDescription.xml": fmi2.model_description(model, native=False).encode("utf-8"),
                          BUILD_INFO: info.encode("utf-8"), **documentation_files(model, "2.0")})
        if guard and not _guard_compiler_found():
            log(f"warning: neither zig nor gcc found: {model}.fmu is built for Python hosts only (fmpy, "
                "libcosimpy), without the C guard that checks every FMI call; pip install ziglang")
        elif guard:
            from .guard import add_guard
            add_guard(fmu, interface_header=c_header(model))
        problems = validate_fmu(str(fmu))
        if problems:
            raise BuildError(f"{model}.fmu failed fmpy validation: " + "; ".join(problems))
        return place(fmu, out_dir / f"{model}.fmu")
