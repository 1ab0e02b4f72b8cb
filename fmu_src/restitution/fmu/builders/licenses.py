"""The license files every FMU carries (``documentation/licenses/``, entry point ``license.txt``), and
the whole ``documentation/`` folder of an FMU: the project's MIT license, which asks that its notice
travel with every copy, and, in the pythonfmu FMUs, which bundle pythonfmu's Python runtime and its
binary behind the guard, pythonfmu's own MIT license taken from the installed distribution (so it is
the build's business, not the describer's: it reads what is installed)."""
from __future__ import annotations

from importlib import metadata

from ...about import LICENSE_FILE, VERSION
from ..describe.documentation import INDEX, index_html

__all__ = ["LICENSES", "license_files", "documentation_files"]

LICENSES = "documentation/licenses/"


def _pythonfmu_license() -> tuple[str, str]:
    """(version, license text) of the installed pythonfmu."""
    dist = metadata.distribution("pythonfmu")
    names = [str(f) for f in dist.files or () if f.name.upper().startswith(("LICENSE", "COPYING"))]
    if not names:
        raise FileNotFoundError(f"pythonfmu {dist.version} is installed without its license file; "
                                "reinstall it from a wheel (pip install --force-reinstall pythonfmu)")
    return dist.version, dist.locate_file(names[0]).read_text(encoding="utf-8")


def license_files(bundles_pythonfmu: bool) -> dict[str, bytes]:
    """Archive name -> content of the license files of one FMU."""
    entry = [f"restitution {VERSION}", "", LICENSE_FILE.read_text(encoding="utf-8")]
    files = {}
    if bundles_pythonfmu:
        version, text = _pythonfmu_license()
        entry += ["", f"This FMU also contains pythonfmu {version} (its Python package in resources/pythonfmu/ "
                      "and its binary behind the restitution guard), under the license in pythonfmu.txt."]
        files[LICENSES + "pythonfmu.txt"] = text.encode("utf-8")
    files[LICENSES + "license.txt"] = ("\n".join(entry).rstrip("\n") + "\n").encode("utf-8")
    return files


def documentation_files(model: str, fmi_version: str = "2.0", native: bool = False) -> dict[str, bytes]:
    """Archive name -> content of everything below ``documentation/`` of one FMU of ``model``: the
    license files and ``index.html``. ``native``: the native C FMU of ``fmi_version`` (co-simulation and
    model exchange, its own ranges); else the pythonfmu FMU (FMI 2.0 co-simulation, bundles pythonfmu)."""
    files = license_files(bundles_pythonfmu=not native)
    files[INDEX] = index_html(model, fmi_version, native).encode("utf-8")
    return files
