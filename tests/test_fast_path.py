"""The scalar fast path of restitution.impact (Python floats) gives the same bits as the
general path (numpy scalars), for every option: it is an optimisation, not a second model."""
import math

import numpy as np
import pytest

import restitution as r
from restitution.model import ImpactResult, impact

FLAGS = {"plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative", "valid"}


def _cases(n, seed=5):
    rng = np.random.default_rng(seed)
    mats = list(r.MATERIALS.values())
    for k in range(n):
        a, b = mats[rng.integers(len(mats))], mats[rng.integers(len(mats))]
        d = 10 ** rng.uniform(-3.5, -1.5)
        t = d * 10 ** rng.uniform(-1.5, 1.0)
        v = 0.0 if k % 17 == 0 else 10 ** rng.uniform(-4, 2.5)
        args = (float(v), a.E, a.nu, a.Sy, a.rho, float(d), b.E, b.nu, b.Sy, b.rho, float(t))  # rho: int
        options = dict(restitution_model=("e45", "e44")[rng.integers(2)],
                       zener_method="ode" if k % 24 == 5 else ("exact", "paper_fit", "linear")[rng.integers(3)],
                       plasticity=("off", "on", "auto", 0, 1, 2)[rng.integers(6)],
                       plate_waves=("off", "on", "auto")[rng.integers(3)],
                       effect_tolerance=(0.0, 1e-6, 1e-3)[rng.integers(3)])
        yield args, options


@pytest.mark.parametrize("validate", [True, False])
def test_float_fast_path_matches_general_path_bit_for_bit(validate):
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


def test_python_ints_take_the_fast_path_with_the_same_bits(monkeypatch):
    """Unvalidated Python ints (the presets' densities are ints) give what their float values give."""
    from restitution import model

    calls = []
    fast = model._impact_scalar
    monkeypatch.setattr(model, "_impact_scalar", lambda *a: calls.append(1) or fast(*a))
    for k, (args, options) in enumerate(_cases(200, seed=9)):
        assert isinstance(args[4], int) and isinstance(args[9], int)
        mixed = list(args)  # densities stay ints; some speeds and thicknesses become ints too
        if k % 3 == 0:
            mixed[0] = int(round(args[0]))
        mixed[3] = int(args[3]) if float(args[3]).is_integer() else args[3]
        got = impact(*mixed, **options, validate=False).as_dict()
        want = impact(*[np.float64(x) for x in mixed], **options, validate=False).as_dict()
        for name, value in got.items():
            assert type(value) is (bool if name in FLAGS else float), name
            assert value == want[name] or (math.isnan(value) and math.isnan(want[name])), (name, mixed, options)
    assert len(calls) == 200  # every int call took the fast path (np.float64 calls do not)


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
    for k in range(7):  # elementwise equal to the scalar call (to rounding: numpy vs math)
        one = impact(float(v[k]), 207e9, 0.3, 2e9, 7861.0, 6.35e-3, 69e9, 0.33, 0.29e9, 2700.0, 6.35e-3)
        for name, value in one.as_dict().items():
            assert getattr(res, name)[k] == pytest.approx(value, rel=1e-13, abs=0.0) or \
                getattr(res, name)[k] == value, name


def test_slave_one_pass_getters_return_what_the_per_variable_getters_return():
    """SpherePlateImpact.get_real/get_boolean (one evaluation, one pass) against pythonfmu's getters."""
    from pythonfmu import Boolean, Real
    from sphere_plate_impact_slave import SpherePlateImpact

    slave = SpherePlateImpact(instance_name="t", visible=False)
    real_out = [v.value_reference for v in slave.vars.values() if isinstance(v, Real) and v.causality.name == "output"]
    bool_out = [v.value_reference for v in slave.vars.values()
                if isinstance(v, Boolean) and v.causality.name == "output"]
    vr = {v.name: v.value_reference for v in slave.vars.values()}

    def same(got, vrs, cast):
        want = [cast(slave.vars[k].getter()) for k in vrs]
        assert len(got) == len(want) and all(a == b or (a != a and b != b) for a, b in zip(got, want))

    for step in range(5):
        if step == 1:
            slave.set_real([vr["v_approach"]], [2.3])  # stale: get_real evaluates first
        if step == 2:
            slave.set_real([vr["plate.nu"]], [0.5])  # invalid: NaN / False
        if step == 3:
            slave.set_real([vr["plate.nu"]], [0.33])
            slave.set_integer([vr["zener_method"]], [2])
        if step == 4:
            slave.reset()
        got_r, got_b = slave.get_real(real_out), slave.get_boolean(bool_out)
        same(got_r, real_out, float)
        same(got_b, bool_out, bool)
        if step == 2:
            assert all(x != x for x in got_r) and not any(got_b)
        else:
            assert all(x == x for x in got_r)
    # inputs and parameters mixed in: pythonfmu's path
    assert slave.get_real([vr["v_approach"], real_out[0]]) == [slave.vars[vr["v_approach"]].getter(),
                                                              slave.get_real(real_out[:1])[0]]
