"""One impact in scalars: Python floats, ints and numpy scalars all take the one pipeline's
scalar mode (converted to float first), so they give the same values and plain Python types;
arrays take its array mode, equal within the conditioning (tests/agree.py)."""
import math

import numpy as np
import pytest

from restitution.model import ImpactResult, impact

from agree import assert_agree, stack
from cases import random_preset_bodies

FLAGS = {"plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative", "valid",
         "contact_ends", "concurrent", "edge_clear"}


def _cases(n, seed=5):
    rng = np.random.default_rng(seed)
    for k in range(n):
        a, b, d, t = random_preset_bodies(rng)
        v = 0.0 if k % 17 == 0 else 10 ** rng.uniform(-4, 2.5)
        args = (float(v), a.E, a.nu, a.Sy, a.rho, float(d), b.E, b.nu, b.Sy, b.rho, float(t))  # rho: int
        options = dict(restitution_model=("e45", "e44")[rng.integers(2)],
                       zener_method="ode" if k % 24 == 5 else ("exact", "paper_fit", "linear")[rng.integers(3)],
                       plasticity=("off", "on", "auto", 0, 1, 2)[rng.integers(6)],
                       plate_waves=("off", "on", "auto")[rng.integers(3)],
                       effect_tolerance=(0.0, 1e-6, 1e-3)[rng.integers(3)])
        yield args, options


@pytest.mark.parametrize("validate", [True, False])
def test_numpy_scalars_give_what_python_floats_give(validate):
    n_compared = 0
    for args, options in _cases(600):
        fast = impact(*[float(x) for x in args], **options, validate=validate)
        general = impact(*[np.float64(x) for x in args], **options, validate=False)
        assert isinstance(fast, ImpactResult)
        got, want = fast.as_dict(), general.as_dict()
        assert list(got) == list(want)
        for name, value in got.items():
            assert type(value) is (bool if name in FLAGS else float), (name, type(value))
            assert value == want[name] or (math.isnan(value) and math.isnan(want[name])), (name, args, options)
        n_compared += 1
    assert n_compared == 600


def test_python_ints_give_what_their_float_values_give():
    """Unvalidated Python ints (the presets' densities are ints) are converted exactly below 2^53."""
    for k, (args, options) in enumerate(_cases(200, seed=9)):
        assert isinstance(args[4], int) and isinstance(args[9], int)
        mixed = list(args)  # densities stay ints; some speeds and thicknesses become ints too
        if k % 3 == 0:
            mixed[0] = int(round(args[0]))
        mixed[3] = int(args[3]) if float(args[3]).is_integer() else args[3]
        got = impact(*mixed, **options, validate=False).as_dict()
        want = impact(*[float(x) for x in mixed], **options, validate=False).as_dict()
        for name, value in got.items():
            assert type(value) is (bool if name in FLAGS else float), name
            assert value == want[name] or (math.isnan(value) and math.isnan(want[name])), (name, mixed, options)


def test_fast_result_behaves_like_a_dataclass_instance():
    args = (2.3, 207e9, 0.3, 2e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.29e9, 2700.0, 6.35e-3)
    fast = impact(*args)
    general = impact(*map(np.float64, args))
    assert fast == general and hash(repr(fast)) == hash(repr(general))
    with pytest.raises(AttributeError):  # still frozen
        fast.e = 0.0
    import pickle
    assert pickle.loads(pickle.dumps(fast)) == fast


def test_array_path_outputs_are_fresh_and_do_not_alias_inputs():
    v = np.linspace(0.0, 5.0, 7)
    t = np.full(7, 6.35e-3)
    res = impact(v, 207e9, 0.3, 2e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.29e9, 2700.0, t)
    arrays = [getattr(res, name) for name in res.as_dict() if name != "valid"]
    for a in arrays:
        assert a.shape == (7,) and not np.shares_memory(a, v) and not np.shares_memory(a, t)
    for i, a in enumerate(arrays):
        for b in arrays[i + 1:]:
            assert not np.shares_memory(a, b)
    ones = stack([impact(float(v[k]), 207e9, 0.3, 2e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.29e9, 2700.0, 6.35e-3)
                  for k in range(7)])
    params = dict(sphere_E=207e9, sphere_nu=0.3, sphere_Sy=2e9, sphere_rho=7861.0, sphere_d=6.35e-3,
                  plate_E=69e9, plate_nu=0.33, plate_Sy=0.29e9, plate_rho=2700.0, plate_t=t)
    assert_agree(res, ones, v, params, "array vs scalar")
