"""The package's identity: its version, authors and license, in one place.

pyproject.toml reads :data:`VERSION` (``[tool.setuptools.dynamic]``), ``restitution.__version__`` is
it, and the FMU build writes all of these into every modelDescription.xml and puts the license text
into every FMU's ``documentation/``. ``LICENSE.txt`` beside this file is the repository's LICENSE,
shipped with the package so that an installed package can build FMUs that carry it.
"""
from pathlib import Path

VERSION = "0.3.0"
AUTHOR = "restitution developers"
LICENSE = "MIT"  # SPDX identifier
COPYRIGHT = "Copyright (c) 2026 the restitution developers"
LICENSE_FILE = Path(__file__).with_name("LICENSE.txt")
