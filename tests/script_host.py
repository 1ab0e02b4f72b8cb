"""The scripted plain C host, tests/c_host/fmi_script_host.c, for the FMI 2.0 and the FMI 3.0 FMUs: its
build (one source, ``-DFMI_VERSION=2|3``, for Linux with gcc or for win64 with mingw-w64) and what a
script needs to know of an FMU (its version, GUID or instantiation token, value references, and which
script command gets and sets each variable: ``real``, ``integer``, ``enumeration`` or ``boolean``)."""
from __future__ import annotations

import subprocess
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

HOST_SOURCE = Path(__file__).resolve().parent / "c_host" / "fmi_script_host.c"
WARNINGS = ["-O2", "-Wall", "-Wextra", "-Werror"]
MINGW = "x86_64-w64-mingw32-gcc"

#: the script command suffix of each modelDescription type (FMI 2.0 gets and sets an Enumeration as an
#: Integer, FMI 3.0 with the Int64 functions; the host knows which)
KINDS = {"Real": "real", "Integer": "integer", "Float64": "real", "Int32": "integer", "Enumeration": "enumeration",
         "Boolean": "boolean"}


def build_host(exe: Path, fmi_version: int = 2, cc: str = "gcc", flags=()) -> Path:
    """Compile the host for ``fmi_version`` (2 or 3) with ``cc`` (gcc, or mingw-w64 for win64) into ``exe``;
    a failed build raises with the compiler's messages."""
    cmd = [cc, *WARNINGS, *flags, f"-DFMI_VERSION={fmi_version}", "-o", str(exe), str(HOST_SOURCE)]
    cmd += ["-D__USE_MINGW_ANSI_STDIO=1", "-static", "-static-libgcc"] if cc == MINGW else ["-ldl"]
    build = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    if build.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}\n{build.stderr}")
    return exe


@dataclass(frozen=True)
class Interface:
    """What the script host needs of one FMU."""

    version: int  #: 2 or 3
    token: str  #: the GUID (FMI 2.0) or instantiation token (FMI 3.0)
    identifier: str  #: the co-simulation modelIdentifier
    vr: dict  #: name -> value reference
    kind: dict  #: name -> "real", "integer", "enumeration" or "boolean"

    @property
    def binary_dirs(self) -> tuple[str, str]:
        """(Linux, Windows) folders of binaries/ for this FMI version."""
        return ("linux64", "win64") if self.version == 2 else ("x86_64-linux", "x86_64-windows")

    def set(self, slot: int, name: str, value) -> str:
        """The script line that sets ``name`` to ``value`` with the call its type needs."""
        kind = self.kind[name]
        text = repr(float(value)) if kind == "real" else str(int(value))
        return f"set_{kind} {slot} {self.vr[name]} {text}"


def interface(fmu: Path) -> Interface:
    with zipfile.ZipFile(fmu) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    version = 3 if root.get("fmiVersion", "").startswith("3") else 2
    vr, kind = {}, {}
    for sv in root.find("ModelVariables"):
        tag = sv[0].tag if version == 2 else sv.tag  # FMI 2.0: <ScalarVariable><Real/>; FMI 3.0: <Float64/>
        vr[sv.get("name")] = int(sv.get("valueReference"))
        kind[sv.get("name")] = KINDS.get(tag, tag)
    token = root.get("guid") if version == 2 else root.get("instantiationToken")
    return Interface(version, token, root.find("CoSimulation").get("modelIdentifier"), vr, kind)
