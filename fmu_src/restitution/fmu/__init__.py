"""Building the project's FMUs from the installed package (``python -m restitution.fmu build``).

The interface tables (``table.py``, ``models/<model>/variables.py``), the slave scripts (``slaves/``),
the plain-C-host loader (``native_host/``) and the build ship with the package, so an installed
``restitution[fmu]`` builds the same FMUs as a source checkout. The build is imported on first use:
the pythonfmu FMUs bundle the interface tables, never the build.
"""
__all__ = ["FMUS", "BuildError", "build_all", "build_one", "default_fmu", "default_fmu_dir"]


def __getattr__(name):
    if name in __all__:
        from . import build
        return getattr(build, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
