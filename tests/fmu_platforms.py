"""Which platforms a built FMU has binaries for, read from the archive (never guessed from the tools on
this machine), what the FMI standard calls a binaries/ folder, what the FMU declares about its
platforms, and why a platform's binary is missing.

A test that needs one platform's binary (Windows, macOS, Linux aarch64) calls :func:`skip_unless_built`:
it skips with one line naming the missing compiler where the build did not produce that binary (neither
mingw-w64 nor zig for Windows; zig, the ``ziglang`` package, for the others), and fails where the compiler
is there but the binary is not in the archive (the build lost it).

As a script, ``python tests/fmu_platforms.py DIR`` prints the binary platforms of every FMU a build wrote
into DIR (``DIR/*.fmu``, ``DIR/fmi2/``, ``DIR/fmi3/``) and exits 1 when :func:`platform_problems`
finds any (.ci/run runs it on a build made without a cross compiler).
"""
from __future__ import annotations

import json
import sys
import zipfile
from pathlib import Path, PurePosixPath
from xml.etree import ElementTree as ET

#: FMI 2.0 (section 2.3, "binaries"): the platform folders the standard names, and the shared
#: library's suffix on each.
FMI2_PLATFORMS = {"win32": ".dll", "win64": ".dll", "linux32": ".so", "linux64": ".so",
                  "darwin32": ".dylib", "darwin64": ".dylib"}
#: FMI 3.0 (section 2.5.1.4): a platform tuple <arch>-<sys> of these architectures and systems (the
#: optional -<abi> names a static library, which no build here writes).
FMI3_ARCHITECTURES = ("aarch32", "aarch64", "riscv32", "riscv64", "x86", "x86_64", "ppc32", "ppc64")
FMI3_SYSTEMS = {"darwin": ".dylib", "linux": ".so", "windows": ".dll"}
#: The binaries/ folders of every native FMU, by FMI version, where the build has every compiler (gcc and
#: zig): FMI 3.0 x86_64 and aarch64 Linux, x86_64 Windows, x86_64 and aarch64 macOS; FMI 2.0 names only
#: linux64, win64 and darwin64 of them (darwin64: one universal file for both macOS architectures).
NATIVE_FOLDERS = {"2.0": ("darwin64", "linux64", "win64"),
                  "3.0": ("aarch64-darwin", "aarch64-linux", "x86_64-darwin", "x86_64-linux", "x86_64-windows")}
#: How to get the compiler of each platform the native build targets (restitution.fmu.builders.toolchains).
INSTALL = {"x86_64-linux": "apt-get install gcc",
           "x86_64-windows": "apt-get install gcc-mingw-w64-x86-64, or pip install ziglang",
           "aarch64-linux": "pip install ziglang", "x86_64-darwin": "pip install ziglang",
           "aarch64-darwin": "pip install ziglang"}


def library_suffix(fmi_version: str, folder: str) -> str | None:
    """The shared library suffix of the binaries/ ``folder`` the standard of ``fmi_version`` names, or
    None when it names no such folder."""
    if fmi_version.startswith("2."):
        return FMI2_PLATFORMS.get(folder)
    arch, _, system = folder.partition("-")
    return FMI3_SYSTEMS.get(system) if arch in FMI3_ARCHITECTURES else None


def _names(fmu: Path) -> list[str]:
    with zipfile.ZipFile(fmu) as z:
        return z.namelist()


def _read(fmu: Path, member: str) -> bytes | None:
    with zipfile.ZipFile(fmu) as z:
        return z.read(member) if member in z.namelist() else None


def fmi_version(fmu: Path) -> str:
    return ET.fromstring(_read(fmu, "modelDescription.xml")).get("fmiVersion")


def model_identifiers(fmu: Path) -> set[str]:
    """The modelIdentifier of every interface the modelDescription declares."""
    root = ET.fromstring(_read(fmu, "modelDescription.xml"))
    return {node.get("modelIdentifier") for node in root
            if node.tag in ("CoSimulation", "ModelExchange", "ScheduledExecution")}


def binary_folders(fmu: Path) -> dict[str, set[str]]:
    """binaries/<folder>/ -> the file names in it, as the archive holds them."""
    folders: dict[str, set[str]] = {}
    for name in _names(fmu):
        parts = PurePosixPath(name).parts
        if len(parts) >= 3 and parts[0] == "binaries" and not name.endswith("/"):
            folders.setdefault(parts[1], set()).add("/".join(parts[2:]))
    return folders


def declared_platforms(fmu: Path) -> list[str] | None:
    """The platforms the build records in the FMU (resources/build_info.json "platforms"; the native
    builds write it), or None when it records none."""
    data = _read(fmu, "resources/build_info.json")
    return None if data is None else json.loads(data).get("platforms")


def build_configuration_platforms(fmu: Path) -> list[str | None]:
    """The ``platform`` of every BuildConfiguration of an FMI 3.0 ``sources/buildDescription.xml`` (None:
    one without, for every platform); [] without a buildDescription."""
    data = _read(fmu, "sources/buildDescription.xml")
    if data is None:
        return []
    return [config.get("platform") for config in ET.fromstring(data).iter("BuildConfiguration")]


def platform_problems(fmu: Path) -> list[str]:
    """What is wrong between the platforms ``fmu`` declares and the binaries it holds: a binaries/ folder
    the standard does not name, or without ``<modelIdentifier><suffix>`` for every modelIdentifier; a
    platform declared (build_info.json) without its binary, or a binary folder not declared there; a
    buildDescription platform that is not a platform tuple; an FMI 3.0 buildDescription naming a
    source file sources/ lacks. Empty when all agree."""
    version = fmi_version(fmu)
    folders = binary_folders(fmu)
    problems = []
    for folder, files in sorted(folders.items()):
        suffix = library_suffix(version, folder)
        if suffix is None:
            problems.append(f"binaries/{folder}: not a platform folder of FMI {version}")
            continue
        for identifier in sorted(model_identifiers(fmu)):
            if f"{identifier}{suffix}" not in files:
                problems.append(f"binaries/{folder}: no {identifier}{suffix}")
    declared = declared_platforms(fmu)
    if declared is not None:
        problems += [f"declares {p} (build_info.json) without binaries/{p}/" for p in declared if p not in folders]
        problems += [f"binaries/{p}/ not declared in build_info.json" for p in sorted(folders) if p not in declared]
    for platform in build_configuration_platforms(fmu):
        if platform is not None and library_suffix("3.0", platform) is None:
            problems.append(f"buildDescription.xml: platform {platform!r} is not an FMI 3.0 platform tuple")
    data = _read(fmu, "sources/buildDescription.xml")
    if data is not None:
        names = set(_names(fmu))
        problems += [f"buildDescription.xml: sources/{f.get('name')} missing"
                     for f in ET.fromstring(data).iter("SourceFile") if f"sources/{f.get('name')}" not in names]
    return problems


def windows_folder(fmu: Path) -> str:
    """The Windows x64 binaries/ folder of the FMU's FMI version."""
    return "win64" if fmi_version(fmu).startswith("2.") else "x86_64-windows"


def skip_unless_built(fmu: Path, platform: str = "win64") -> str:
    """The binaries/ folder of ``platform`` (a binaries/ folder of either FMI version: win64 or
    x86_64-windows, darwin64, aarch64-linux, ...) in ``fmu``, which the build produced; skips, naming the
    compiler, where the archive has no binary there because that compiler is not installed (see
    restitution.fmu.builders.toolchains); fails where the compiler is there and the binary is still missing."""
    from restitution.fmu.builders import toolchains

    version = fmi_version(fmu)
    folders = toolchains.folders(version)
    folder = platform if platform in folders else toolchains.platform(platform).folder(version)
    if folder is None:
        raise ValueError(f"FMI {version} has no binaries/ folder for {platform}")
    suffix = library_suffix(version, folder)
    if all(f"{identifier}{suffix}" in binary_folders(fmu).get(folder, ()) for identifier in model_identifiers(fmu)):
        return folder
    try:
        compilers = [toolchains.compiler(p).name for p in folders[folder]]
    except toolchains.ToolchainMissing as exc:
        import pytest

        pytest.skip(f"{folder} binaries not built here: {exc}")
    raise AssertionError(f"{fmu.name} has no binaries/{folder}/ although {', '.join(compilers)} is there: the "
                         "build skipped it (see its warnings)")


def summary(out_dir: Path) -> tuple[list[str], list[str]]:
    """(one line per FMU of a build's output directory: its binary platforms and whether it ships
    sources, the problems found)."""
    out_dir = Path(out_dir)
    lines, problems = [], []
    for fmu in sorted(out_dir.glob("*.fmu")) + sorted(out_dir.glob("fmi2/*.fmu")) + sorted(out_dir.glob("fmi3/*.fmu")):
        name = fmu.relative_to(out_dir).as_posix()
        sources = any(n.startswith("sources/") and n.endswith(".c") for n in _names(fmu))
        lines.append(f"{name}: binaries {', '.join(sorted(binary_folders(fmu))) or 'none'}"
                     + (" + sources/" if sources else ""))
        problems += [f"{name}: {p}" for p in platform_problems(fmu)]
    return lines, problems


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python tests/fmu_platforms.py DIR   (a build's --out directory)", file=sys.stderr)
        return 2
    lines, problems = summary(Path(argv[0]))
    if not lines:
        print(f"{argv[0]}: no FMU found", file=sys.stderr)
        return 1
    print("\n".join(lines))
    for problem in problems:
        print(f"error: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
