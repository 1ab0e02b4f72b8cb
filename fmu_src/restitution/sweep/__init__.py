"""Design-space sweeps of the sphere-on-plate COR on Dask: a grid or random sample over any FMU
parameter and the approach speed, evaluated by the vectorized package or by the FMU itself.
From the command line::

    restitution sweep --pair s2_tool_steel/al_6061 \\
        --grid v_approach=geomspace:0.1:10:60 --grid t_over_d=geomspace:0.1:10:50 --out map.csv

See docs/sweeps.md. Needs ``dask[distributed]`` (the ``sweep`` extra); the FMU back end
needs the ``fmu`` extra, the plot matplotlib, Parquet output pyarrow.
"""
from .backends import Backend, FmuBackend, PackageBackend, code_fingerprint, get_backend, release_fmus
from .cluster import machine_workers, open_client
from .compare import compare_results
from .run import run_sweep
from .result import SweepResult
from .table import COLUMNS, read_table
from .spec import CODES, INPUTS, OUTPUTS, SweepSpec, canonical_name, load_spec, resolve_pair

__all__ = ["SweepSpec", "run_sweep", "SweepResult", "open_client", "machine_workers", "compare_results",
           "read_table", "load_spec", "Backend", "PackageBackend", "FmuBackend", "get_backend",
           "release_fmus", "code_fingerprint", "canonical_name", "resolve_pair", "INPUTS", "OUTPUTS",
           "CODES", "COLUMNS"]
