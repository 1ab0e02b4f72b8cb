"""Print the SIMD dispatch targets numpy has compiled in and this CPU enables, space-separated:
the value of NPY_DISABLE_CPU_FEATURES that makes numpy fall back to its baseline kernels."""
from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

print(" ".join(target for target in __cpu_dispatch__ if __cpu_features__.get(target)))
