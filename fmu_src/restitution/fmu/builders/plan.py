"""The build plan: which FMUs a build makes, for which platforms, with which compiler; which of them a
directory lacks or holds stale (building a plan is :mod:`.products`'s).

* :func:`full_plan`: every FMU of the project, the native ones for every platform (what ``python -m
  restitution.fmu build`` builds, and what :func:`~restitution.fmu.builders.products.default_fmu` keeps
  complete by default);
* :func:`model_plan`: one model's pythonfmu FMU, ``<model>.fmu``: what the Quickstart demo runs, built in
  seconds with no zig (its guard is gcc's, for x86_64-linux, the host);
* :func:`steps`: a plan's products, platforms and compilers, as the build will meet them;
* :func:`stale`: why a product must be built in a directory (missing, built from other sources, lacking
  a platform this machine can build), or None. :func:`restitution.fmu.builders.products.run` builds a plan.

A native FMU records the binaries/ folders it holds (``resources/build_info.json``: ``platforms``); a
directory whose native FMU lacks one that a compiler here can build (an FMU built where zig was missing,
or for fewer platforms) is not the full set, and a full plan rebuilds that FMU.
"""
from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

from . import toolchains
from .sources import BACKENDS, BUILD_INFO, FMUS, PYTHONFMU_FOLDERS, VERSION_DIRS, native_source_hash, source_hash
from .toolchains import pythonfmu_label

__all__ = ["Product", "Step", "full_plan", "model_plan", "steps", "stale", "to_build", "zig_targets", "build_info"]

#: The kinds of FMU, with the folder below the output directory and the FMI version of each.
KINDS = {"pythonfmu": ("", "2.0"), "fmi2": ("fmi2/", "2.0"), "fmi3": ("fmi3/", "3.0")}


@dataclass(frozen=True)
class Product:
    """One FMU of a build: ``<model>.fmu`` (pythonfmu) or ``fmi2/<model>.fmu``, ``fmi3/<model>.fmu``
    (native C) with the binaries/ folders ``folders`` (None: every one of its FMI version)."""

    model: str
    kind: str = "pythonfmu"
    folders: tuple[str, ...] | None = None

    @property
    def native(self) -> bool:
        return self.kind != "pythonfmu"

    @property
    def fmi_version(self) -> str:
        return KINDS[self.kind][1]

    @property
    def name(self) -> str:
        """Its path below the output directory: ``SpherePlateImpact.fmu``, ``fmi2/SpherePlateImpact.fmu``."""
        return f"{KINDS[self.kind][0]}{self.model}.fmu"

    def path(self, out_dir) -> Path:
        return Path(out_dir) / self.name

    def planned_folders(self) -> tuple[str, ...]:
        """The binaries/ folders it is built with (pythonfmu: those of pythonfmu's own binaries)."""
        if not self.native:
            return PYTHONFMU_FOLDERS
        return tuple(f for f in toolchains.folders(self.fmi_version) if self.folders is None or f in self.folders)

    def buildable_folders(self) -> tuple[str, ...]:
        """Of :meth:`planned_folders`, those a compiler here builds (every platform of the folder)."""
        mine = steps([self])
        blocked = {s.folder for s in mine if s.compiler is None}
        return tuple(dict.fromkeys(s.folder for s in mine if s.folder not in blocked))


class Step(NamedTuple):
    """One platform's binary of one product: its compiler here ("gcc", "zig cc -target ...", the pythonfmu
    label), or None and why (``missing``)."""

    product: str
    folder: str
    platform: str
    compiler: str | None
    missing: str = ""


def full_plan() -> list[Product]:
    """Every FMU of the project: the pythonfmu ones, then the native FMI 2.0 and FMI 3.0 ones, every platform."""
    plan = [Product(model) for model in FMUS]
    return plan + [Product(model, VERSION_DIRS[v]) for v in VERSION_DIRS for model in BACKENDS]


def model_plan(model: str = "SpherePlateImpact") -> list[Product]:
    """``<model>.fmu`` alone, the pythonfmu FMU: what the Quickstart demo runs."""
    if model not in FMUS:
        raise KeyError(f"{model}: not one of {', '.join(FMUS)}")
    return [Product(model)]


def steps(plan, guard: bool = True) -> list[Step]:
    """Every (product, platform) of ``plan`` in build order, with the compiler that builds it here."""
    out = []
    for product in plan:
        if not product.native:
            out.append(Step(product.name, ", ".join(PYTHONFMU_FOLDERS), "x86_64-linux", pythonfmu_label(guard)))
            continue
        for folder in product.planned_folders():
            for target in toolchains.folders(product.fmi_version)[folder]:
                try:
                    cc = toolchains.compiler(target)
                except toolchains.ToolchainMissing as exc:
                    out.append(Step(product.name, folder, target.name, None, str(exc)))
                else:
                    out.append(Step(product.name, folder, target.name, toolchains.compiler_label(target, cc)))
    return out


def zig_targets(plan) -> list[toolchains.Platform]:
    """The platforms ``plan`` compiles with zig, each once, in build order."""
    names = [s.platform for s in steps([p for p in plan if p.native]) if (s.compiler or "").startswith("zig cc")]
    return [toolchains.platform(name) for name in dict.fromkeys(names)]


def build_info(fmu: Path) -> dict | None:
    try:
        with zipfile.ZipFile(fmu) as z:
            return json.loads(z.read(BUILD_INFO))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None


def stale(product: Product, out_dir) -> str | None:
    """Why ``product`` must be built into ``out_dir``: "missing", "built from other sources" (the source
    hash it records is not the installed package's), "lacks <folders>" (a native FMU without a binaries/
    folder a compiler here builds: not the full set); None when it is up to date, or when nothing here
    can build it (a native FMU without any compiler)."""
    if product.native and not product.buildable_folders():
        return None
    fmu = product.path(out_dir)
    if not fmu.is_file():
        return "missing"
    info = build_info(fmu)
    expected = native_source_hash(product.model) if product.native else source_hash(product.model)
    if info is None or info.get("source_hash") != expected:
        return "built from other sources"
    if product.native:
        lacking = [f for f in product.buildable_folders() if f not in info.get("platforms", ())]
        if lacking:
            return f"lacks binaries/{', binaries/'.join(lacking)}"
    return None


def to_build(plan, out_dir) -> list[tuple[Product, str]]:
    """(product, why) for each product of ``plan`` that must be built into ``out_dir`` (:func:`stale`)."""
    return [(p, why) for p in plan for why in [stale(p, out_dir)] if why is not None]
