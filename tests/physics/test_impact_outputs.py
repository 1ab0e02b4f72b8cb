"""``impact(outputs=...)``: the asked outputs only, each the very value the full result holds.

The selection runs the full pipeline's own steps, skipping those no asked output depends on, so the
same operations give the same bits: bit identity is the right comparison here (same code path, same
process), over random in-domain cases, every option, scalars and arrays."""
from __future__ import annotations

import math

import numpy as np
import pytest

import restitution as r
from restitution.model import RECORD, RECORD_FLAGS, output_dependencies
from tests.cases import random_cases

#: zener_method "ode" integrates an ODE per case: a few scalar cases only
METHODS = ("exact", "paper_fit", "linear")
MODES = ("auto", "on", "off")


def _options(rng):
    return dict(zener_method=METHODS[rng.integers(len(METHODS))], plasticity=MODES[rng.integers(3)],
                plate_waves=MODES[rng.integers(3)], restitution_model=("e45", "e44")[rng.integers(2)],
                plate_edge_distance=(math.inf, 0.0, float(10 ** rng.uniform(-4, 0)))[rng.integers(3)])


def _subset(rng):
    k = int(rng.integers(1, 6))
    return tuple(RECORD[i] for i in rng.choice(len(RECORD), size=k, replace=False))


def _same_bits(a, b):
    """Equal to the last bit (NaN equal to NaN, -0.0 told from 0.0), of the same kind."""
    if isinstance(a, np.ndarray):
        return (isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape
                and a.tobytes() == b.tobytes())
    return type(a) is type(b) and (a == b or (a != a and b != b)) and math.copysign(1, a) == math.copysign(1, b)


@pytest.mark.parametrize("seed", range(6))
def test_arrays_asked_outputs_are_the_full_results(seed):
    rng = np.random.default_rng(seed)
    v, params = random_cases(rng, 400)
    for _ in range(12):
        options, asked = _options(rng), _subset(rng)
        full = r.impact(v, **params, **options, validate=False).as_dict()
        some = r.impact(v, **params, **options, validate=False, outputs=asked)
        assert tuple(some) == asked
        for name in asked:
            assert _same_bits(some[name], full[name]), (name, options)


@pytest.mark.parametrize("seed", range(3))
def test_scalars_asked_outputs_are_the_full_results(seed):
    rng = np.random.default_rng(100 + seed)
    v, params = random_cases(rng, 60)
    for i in range(60):
        options, asked = _options(rng), _subset(rng)
        if i < 3:
            options["zener_method"] = "ode"
        case = {k: float(x[i]) for k, x in params.items()}
        full = r.impact(float(v[i]), **case, **options, validate=False).as_dict()
        some = r.impact(float(v[i]), **case, **options, validate=False, outputs=asked)
        for name in asked:
            assert _same_bits(some[name], full[name]), (name, options)
            assert type(some[name]) is (bool if name in RECORD_FLAGS else float)


def test_e_and_v_rebound_of_a_monte_carlo_are_the_full_results():
    """The case the sweeps and the benchmarks time: one pair, one plate, 10^5 speeds."""
    p = {**r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3).params(),
         **r.Plate(r.MATERIALS["al_6061"], 6.35e-3).params()}
    v = 10 ** np.random.default_rng(7).uniform(-3, 1, 100_000)
    full = r.impact(v, **p)
    some = r.impact(v, **p, outputs=("e", "v_rebound"))
    assert _same_bits(some["e"], full.e) and _same_bits(some["v_rebound"], full.v_rebound)
    assert _same_bits(r.impact(v, **p, outputs="e_ze")["e_ze"], full.e_ze)


def test_asked_arrays_are_their_own():
    v = np.linspace(0.1, 5.0, 50)
    p = {**r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3).params(),
         **r.Plate(r.MATERIALS["al_6061"], 6.35e-3).params()}
    out = r.impact(v, **p, outputs=("e", "V_c", "valid", "m_a"))
    assert out["V_c"].shape == out["m_a"].shape == out["valid"].shape == v.shape
    arrays = list(out.values())
    assert not any(np.shares_memory(a, b) for i, a in enumerate(arrays) for b in arrays[i + 1:] + [v])


@pytest.mark.parametrize("outputs", [("e", "bogus"), ("E",), [], "valid ", (1,), 5, [["e"]]])
def test_unknown_outputs_are_one_line_value_errors(outputs):
    with pytest.raises(ValueError) as info:
        r.impact(1.0, **{**r.Sphere(r.MATERIALS["s2_tool_steel"], 6.35e-3).params(),
                         **r.Plate(r.MATERIALS["al_6061"], 6.35e-3).params()}, outputs=outputs, validate=False)
    assert "\n" not in str(info.value) and "outputs" in str(info.value)


def test_dependencies_close_over_the_record():
    """Every step an output depends on is an output or Zener's whole solution, and the asked output is in
    its own closure; e needs JGM's e_ep and Zener's e_ze but not the contact time."""
    for name in RECORD:
        closure = output_dependencies(name)
        assert name in closure and closure <= set(RECORD) | {"zener"}
    assert output_dependencies("e") == {"e", "e_ep", "e_ze"}
    assert {"T", "zener"} <= output_dependencies("edge_clear")
