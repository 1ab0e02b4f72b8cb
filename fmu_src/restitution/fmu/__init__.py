"""Building the project's FMUs from the installed package (``python -m restitution.fmu build``).

Everything an FMU is made of ships with the package, so an installed ``restitution[fmu]`` builds the
same FMUs as a source checkout:

* ``table.py`` and ``models/<model>/``: each model's interface table (``variables.py``), its pythonfmu
  slave, its native C backend and glue;
* ``cfront/``: the C FMI front (the FMI 2.0 plumbing, written once for every model and both
  implementations); ``physics_c/``: the physics in C99; ``pythonfmu_guard/``: the guard's backend that
  forwards checked calls to pythonfmu, and its Python loader for plain C hosts;
* ``describe/``: every description, header and page written from the tables (pure text);
* ``builders/``: the builders, one per product (pythonfmu, native, the guard), and the entry points.

The build is imported on first use: the pythonfmu FMUs bundle the interface tables, never the build.
An installed wheel carries the built FMUs (``installed_fmus/``): :func:`path` names one, :func:`copy` copies
them out (:mod:`.installed`), and :func:`default_fmu` uses them before building anything.
"""
_BUILD = ["FMUS", "BuildError", "build_all", "build_one", "default_fmu", "default_fmu_dir"]
_INSTALLED = ["path", "copy", "NotInstalled"]
__all__ = [*_BUILD, *_INSTALLED]


def __getattr__(name):
    if name in _BUILD:
        from . import builders
        return getattr(builders, name)
    if name in _INSTALLED:
        from . import installed
        return getattr(installed, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
