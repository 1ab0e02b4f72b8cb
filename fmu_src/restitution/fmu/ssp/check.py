"""Checking an SSP archive: the packaging rules of SSP (section "SSP package") and, for SSP 1.0, the
official XML schemas of the SSD and every SSV (SSP 1.0's normative XML Schema 1.0 files, which fmpy ships
in ``fmpy/ssp/schema``; no SSP 2.0 schema is installable from PyPI, so an SSP 2.0 archive gets the
packaging rules and its references only)."""
from __future__ import annotations

import zipfile
from pathlib import Path, PurePosixPath
from xml.etree import ElementTree as ET

from .package import SSD_ENTRY
from .xml_common import tag

__all__ = ["packaging_problems", "schema_problems", "check_ssp", "schema_dir"]


def schema_dir() -> Path | None:
    """fmpy's folder of the SSP 1.0 schemas, None where fmpy is not installed."""
    try:
        import fmpy.ssp
    except ImportError:
        return None
    folder = Path(fmpy.ssp.__file__).parent / "schema"
    return folder if (folder / "SystemStructureDescription.xsd").is_file() else None


def _bad_name(name: str) -> str:
    path = PurePosixPath(name)
    if "\\" in name or name.startswith("/") or ".." in path.parts or not name:
        return f"entry {name!r}: not a relative path with forward slashes"
    return ""


def packaging_problems(ssp: Path) -> list[str]:
    """What breaks SSP's packaging rules in ``ssp``: a zip holding SystemStructure.ssd at its root, relative
    entry names with '/' (no '..'), each once; every component source and parameter binding source the
    SSD names present in the archive, each FMU below resources/."""
    with zipfile.ZipFile(ssp) as archive:
        names = archive.namelist()
        problems = [p for p in map(_bad_name, names) if p]
        problems += [f"entry {n!r} appears {names.count(n)} times" for n in sorted(set(names)) if names.count(n) > 1]
        if SSD_ENTRY not in names:
            return problems + [f"no {SSD_ENTRY} at the archive's root"]
        root = ET.fromstring(archive.read(SSD_ENTRY))
    for component in root.iter(tag("ssd", "Component")):
        source = component.get("source", "")
        if source not in names:
            problems.append(f"component {component.get('name')}: source {source!r} is not in the archive")
        elif not source.startswith("resources/"):
            problems.append(f"component {component.get('name')}: {source!r} is not below resources/")
    for binding in root.iter(tag("ssd", "ParameterBinding")):
        source = binding.get("source")
        if source is not None and source not in names:
            problems.append(f"parameter binding source {source!r} is not in the archive")
    return problems


def schema_problems(ssp: Path) -> list[str]:
    """Every schema error of the SSD and of each .ssv entry of an SSP 1.0 archive (lxml, fmpy's copy of
    the official schemas); [] for an SSP 2.0 archive (no schema here). RuntimeError without fmpy/lxml."""
    from lxml import etree

    folder = schema_dir()
    if folder is None:
        raise RuntimeError("fmpy is not installed: it ships the SSP 1.0 schemas (pip install fmpy)")
    problems = []
    with zipfile.ZipFile(ssp) as archive:
        ssd = etree.fromstring(archive.read(SSD_ENTRY))
        if not ssd.get("version", "").startswith("1."):
            return []
        documents = [(SSD_ENTRY, ssd, "SystemStructureDescription.xsd")]
        documents += [(n, etree.fromstring(archive.read(n)), "SystemStructureParameterValues.xsd")
                      for n in archive.namelist() if n.endswith(".ssv")]
    schemas = {}
    for name, document, xsd in documents:
        schema = schemas.setdefault(xsd, etree.XMLSchema(file=str(folder / xsd)))
        if not schema.validate(document):
            problems += [f"{name}:{e.line}: {e.message}" for e in schema.error_log]
    return problems


def check_ssp(ssp: Path) -> str:
    """What was checked in ``ssp`` (one phrase); ValueError naming the first problems found."""
    problems = packaging_problems(ssp)
    if not problems:
        problems = schema_problems(ssp)
    if problems:
        raise ValueError(f"{ssp}: " + "; ".join(problems[:5]))
    with zipfile.ZipFile(ssp) as archive:
        version = ET.fromstring(archive.read(SSD_ENTRY)).get("version")
    if version.startswith("1."):
        return "SSP 1.0 schemas and packaging: 0 problems"
    return f"SSP {version} packaging: 0 problems (no SSP {version} schema installed to validate against)"
