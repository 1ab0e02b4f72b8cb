"""Call the compiled native physics (``rst_impact`` of rst_physics.c) from Python through ctypes,
with :func:`restitution.impact`'s argument names, for the equivalence tests and the benchmark."""
from __future__ import annotations

import ctypes
import math
from types import SimpleNamespace

import numpy as np

from restitution.agreement import FLAGS, REALS  # the result record: the C struct is generated from it, in this order
from restitution.fmu.models.sphere_plate_impact.variables import TABLE

_INPUT_REALS = ("v", "sphere_E", "sphere_nu", "sphere_Sy", "sphere_rho", "sphere_d",
                "plate_E", "plate_nu", "plate_Sy", "plate_rho", "plate_t", "plate_edge_distance")
#: What a parameter the caller leaves out is: an unbounded plate, impact()'s default.
_DEFAULTS = {"plate_edge_distance": math.inf}
#: Codes of the FMU's Integer parameters, which rst_physics.h numbers the same way.
MODEL_CODE = TABLE["restitution_model"].codes
METHOD_CODE = TABLE["zener_method"].codes
MODE_CODE = TABLE["plasticity"].codes
OK, BAD_CODE, UNSUPPORTED = 0, 1, 2


class Inputs(ctypes.Structure):
    _fields_ = ([(n, ctypes.c_double) for n in _INPUT_REALS]
                + [(n, ctypes.c_int) for n in ("restitution_model", "zener_method", "plasticity", "plate_waves")]
                + [("effect_tolerance", ctypes.c_double), ("ode_rtol", ctypes.c_double)])


class Result(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in REALS] + [(n, ctypes.c_int) for n in FLAGS]


class NativePhysics:
    """The library at ``path``; :meth:`impact` mirrors :func:`restitution.impact` for one or many cases."""

    def __init__(self, path):
        self.lib = ctypes.CDLL(str(path))
        self.lib.rst_impact.argtypes = (ctypes.POINTER(Inputs), ctypes.POINTER(Result))
        self.lib.rst_impact.restype = ctypes.c_int

    def call(self, v, params: dict, restitution_model="e45", zener_method="exact", plasticity="auto",
             plate_waves="auto", effect_tolerance=1e-6, ode_rtol=1e-10):
        """(status, Result) of one impact, floats in."""
        inp = Inputs(float(v), *(float(params.get(n, _DEFAULTS.get(n))) for n in _INPUT_REALS[1:]),
                     MODEL_CODE[restitution_model],
                     METHOD_CODE[zener_method], MODE_CODE[plasticity], MODE_CODE[plate_waves],
                     float(effect_tolerance), float(ode_rtol))
        out = Result()
        status = self.lib.rst_impact(ctypes.byref(inp), ctypes.byref(out))
        return status, out

    def impact(self, v, params: dict, **options) -> SimpleNamespace:
        """Every case of the broadcast inputs; arrays named as ImpactResult's fields. Raises on a non-OK status."""
        arrays = np.broadcast_arrays(np.asarray(v, dtype=float), *(np.asarray(params.get(n, _DEFAULTS.get(n)), dtype=float)
                                                                   for n in _INPUT_REALS[1:]))
        shape = arrays[0].shape
        flat = [a.ravel() for a in arrays]
        reals = {n: np.empty(flat[0].size) for n in REALS}
        flags = {n: np.empty(flat[0].size, dtype=bool) for n in FLAGS}
        for i in range(flat[0].size):
            status, out = self.call(flat[0][i], {n: flat[j + 1][i] for j, n in enumerate(_INPUT_REALS[1:])},
                                    **options)
            if status != OK:
                raise RuntimeError(f"rst_impact returned {status} for case {i}")
            for n in REALS:
                reals[n][i] = getattr(out, n)
            for n in FLAGS:
                flags[n][i] = bool(getattr(out, n))
        return SimpleNamespace(**{n: a.reshape(shape) for n, a in {**reals, **flags}.items()})
