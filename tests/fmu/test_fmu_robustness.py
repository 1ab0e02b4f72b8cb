"""SpherePlateImpact.fmu, every implementation (pythonfmu behind the C guard, native FMI 2.0, native
FMI 3.0; all through restitution.cosim.FmuInstance), under bad input, many instances, state round
trips and a million steps (fmpy host); the pythonfmu one also next to a different pythonfmu FMU.

* Every input and parameter set to NaN, +inf, -inf, a negative value, zero where a positive
  value is needed, nu > 0.5, an integer code out of range: the set call returns Error
  (fmi2Error, fmi3Error) and the FMU logs one message naming the variable, its value and the
  allowed range; the previous value is kept, so outputs and steps go on as before (never
  Fatal); another instance stepping alongside is unaffected.
* Eight instances with different materials stepped interleaved give the same bits as one at
  a time, and the package's numbers (within each output's conditioning, restitution.agreement).
* Getting and setting FMU states and (de)serializing them round-trip every variable exactly.
* One million steps in one instance: unchanged results, resident memory growing < 1 MiB.
"""
from __future__ import annotations

import gc
import math
import struct
import sys
import time
from types import SimpleNamespace

import pytest
from fmpy import extract

import restitution as r
from restitution.agreement import disagreements, tolerances
from restitution.cosim import FmiStatusError, FmuInstance, impact_fmu_parameters
from restitution.model import DOMAIN

from cases import runs_ode
from toy_fmu import build_toy_fmu

FMI_OK, FMI_DISCARD, FMI_ERROR, FMI_FATAL = 0, 2, 3, 4

# name: (start value, allowed-range text as logged) -- the public interface contract
INPUTS = {
    "v_approach": (1.0, "0 <= value <= 10000"),
    "sphere.E": (207e9, "100000 <= value <= 1e+13"), "sphere.nu": (0.30, "0 <= value <= 0.5"),
    "sphere.Sy": (2.0e9, "1000 <= value <= 1e+13"), "sphere.rho": (7861.0, "1 <= value <= 100000"),
    "sphere.d": (6.35e-3, "1e-06 <= value <= 10"),
    "plate.E": (69e9, "100000 <= value <= 1e+13"), "plate.nu": (0.33, "0 <= value <= 0.5"),
    "plate.Sy": (0.290e9, "1000 <= value <= 1e+13"), "plate.rho": (2700.0, "1 <= value <= 100000"),
    "plate.t": (6.35e-3, "1e-07 <= value <= 100"),
    "effect_tolerance": (1e-6, "finite and >= 0"),
    "zener.ode_tolerance": (1e-10, "1e-14 <= value <= 1e-2"),
    "restitution_model": (1, "1 = e45 or 2 = e44"),
    "zener_method": (1, "1 = exact, 2 = paper_fit, 3 = linear or 4 = ode"),
    "plasticity": (2, "0 = off, 1 = on or 2 = auto"),
    "plate_waves": (2, "0 = off, 1 = on or 2 = auto"),
}
CODES = {"restitution_model": (1, 2), "zener_method": (1, 4), "plasticity": (0, 2), "plate_waves": (0, 2)}
INF, NAN = math.inf, math.nan
DOMAIN_OF = {"v_approach": "v", **{f"{body}.{p}": f"{body}_{p}" for body in ("sphere", "plate")
                                   for p in ("E", "Sy", "rho")}, "sphere.d": "sphere_d", "plate.t": "plate_t"}


def _bad_values(name):
    if name in CODES:
        low, high = CODES[name]
        return [low - 1, high + 1, 2 ** 31 - 1, -2 ** 31]
    values = [NAN, INF, -INF]
    if name.endswith(".nu"):
        return values + [-0.1, math.nextafter(0.5, INF), 0.7]
    if name in DOMAIN_OF:  # the declared domain (restitution.model.DOMAIN): just outside either end
        low, high = DOMAIN[DOMAIN_OF[name]]
        return values + [-1.0, math.nextafter(low, -INF), high * (1 + 1e-15), 1e300]
    if name == "effect_tolerance":
        return values + [-1.0, -5e-324]
    if name == "zener.ode_tolerance":
        return values + [-1e-10, 0.0, 1e-15, 0.1]
    return values + [-1.0, 0.0]


BAD = [(name, value) for name in INPUTS for value in _bad_values(name)]
REAL_OUTPUTS = {"e": "e", "v_rebound": "v_rebound", "jgm.e": "e_ep", "jgm.V_c": "V_c", "jgm.V_star": "V_star",
                "zener.e": "e_ze", "zener.lambda": "lam", "zener.tau0": "tau0", "zener.t_contact": "t_contact",
                "plate.mass_ratio": "mass_ratio", "plate.v_after": "v_plate"}
OUTPUT_NAMES = list(REAL_OUTPUTS)
BOOL_OUTPUTS = ["valid", "zener.in_range", "jgm.in_range", "e_negative", "effects.plasticity", "effects.plate_waves"]
BOOL_FIELDS = ["valid", "lambda_in_range", "vstar_in_range", "e_negative", "plasticity_used", "plate_waves_used"]
MODELS, METHODS, MODES = r.RESTITUTION_MODELS, r.ZENER_METHODS, r.EFFECT_MODES


def _package_call(settings: dict):
    """(v, params, options) of restitution.impact for a dict of FMU settings (defaults for the rest)."""
    s = {name: start for name, (start, _text) in INPUTS.items()}
    s.update(settings)
    params = {f"{body}_{k}": s[f"{body}.{k}"] for body in ("sphere", "plate")
              for k in ("E", "nu", "Sy", "rho", "d" if body == "sphere" else "t")}
    options = dict(restitution_model=MODELS[s["restitution_model"] - 1], zener_method=METHODS[s["zener_method"] - 1],
                   plasticity=MODES[s["plasticity"]], plate_waves=MODES[s["plate_waves"]],
                   effect_tolerance=s["effect_tolerance"], ode_rtol=s["zener.ode_tolerance"])
    return s["v_approach"], params, options


def reference(settings: dict):
    """The package's result for a dict of FMU settings (defaults for anything not given)."""
    v, params, options = _package_call(settings)
    return r.impact(v, **params, **options)


def assert_outputs(fmu, settings, context=""):
    """Every Real and Boolean output equals the package's within the output's conditioning
    (restitution.agreement: the native FMU's libm and numpy may differ in last bits)."""
    v, params, options = _package_call(settings)
    got = dict(zip(REAL_OUTPUTS.values(), fmu.get_reals(OUTPUT_NAMES)))
    got.update(zip(BOOL_FIELDS, fmu.get(*BOOL_OUTPUTS)))
    problems = disagreements(SimpleNamespace(**got), r.impact(v, **params, **options), *tolerances(v, params, **options))
    assert not problems, (context, problems)


@pytest.fixture(scope="module")
def unzipped(any_version_impact_fmu, tmp_path_factory):
    return extract(str(any_version_impact_fmu), str(tmp_path_factory.mktemp("unzipped")))


GOOD_SETTINGS = {**impact_fmu_parameters(r.Sphere(r.MATERIALS["tungsten_carbide"], 4.76e-3),
                                         r.Plate(r.MATERIALS["brass_260"], 2e-3)), "v_approach": 3.1}


@pytest.fixture(scope="module")
def bystander(any_version_impact_fmu, unzipped):
    """An instance that keeps stepping, with valid values, next to every misbehaving one."""
    with FmuInstance(any_version_impact_fmu, "bystander", unzip_dir=unzipped, parameters=GOOD_SETTINGS) as fmu:
        yield fmu


def _message_for(name, value, allowed):
    return f"{name} = {value!r} is outside the allowed range: {allowed}"


@pytest.mark.parametrize("name,value", BAD, ids=[f"{n}={v!r}" for n, v in BAD])
def test_bad_value_is_refused_and_the_previous_one_kept(any_version_impact_fmu, unzipped, bystander, name, value):
    start, allowed = INPUTS[name]
    with FmuInstance(any_version_impact_fmu, "bad", unzip_dir=unzipped) as bad:
        bad.set(v_approach=2.3)
        bad.do_step(step_size=1e-3)
        bystander.do_step(step_size=1e-3)
        before = bad.get_reals(OUTPUT_NAMES)
        n_before = len(bad.messages)

        with pytest.raises(FmiStatusError) as err:
            bad.set(**{name: value})
        assert err.value.status == FMI_ERROR
        assert bad.messages[n_before:] == [(FMI_ERROR, _message_for(name, value, allowed))]
        assert bad.get(name) == [2.3 if name == "v_approach" else start]  # the previous value, kept
        for _ in range(2):  # and the instance goes on with it
            bad.do_step(step_size=1e-3)
            assert _same(bad.get_reals(OUTPUT_NAMES), before)
        assert_outputs(bad, {"v_approach": 2.3}, "after the refusal")

        # the other instance is unaffected (and re-evaluates: its input changes every time)
        v = 3.1 + 1e-3 * len(bad.messages) + bystander.time
        bystander.set(v_approach=v)
        bystander.do_step(step_size=1e-3)
        assert_outputs(bystander, {**GOOD_SETTINGS, "v_approach": v}, "bystander")

        # refused in a vector call too: all or nothing, with a valid neighbour
        other, other_value = ("plate.t", 3e-3) if name != "plate.t" else ("sphere.d", 4e-3)
        if bad.kind(name) == "Real":
            with pytest.raises(FmiStatusError):
                bad.set(**{other: other_value, name: value})
            assert bad.get(other) == [INPUTS[other][0]]
        assert FMI_FATAL not in [status for status, _ in bad.messages]


def _same(a, b):
    return all(x == y or (math.isnan(x) and math.isnan(y)) for x, y in zip(a, b))


@pytest.mark.parametrize("name,value", [("plate.t", NAN), ("sphere.nu", 0.7), ("zener_method", 9), ("v_approach", -INF)])
def test_bad_value_during_initialization(any_version_impact_fmu, unzipped, name, value):
    """Set in initialization mode (between entering and exiting it): same behaviour."""
    with pytest.raises(FmiStatusError) as err:
        FmuInstance(any_version_impact_fmu, "init", unzip_dir=unzipped, parameters={name: value})
    assert err.value.status == FMI_ERROR and _message_for(name, value, INPUTS[name][1]) in str(err.value)


@pytest.mark.parametrize("name,value", [("sphere.E", 1e13), ("plate.t", 1e-7), ("sphere.d", 1e-6),
                                        ("plate.E", 1e5), ("v_approach", 1e4), ("sphere.rho", 1e5),
                                        ("plate.t", 100.0), ("sphere.Sy", 1e3)])
def test_valid_but_absurd_values_give_the_packages_numbers(any_version_impact_fmu, unzipped, name, value):
    """At the ends of the declared domain (physically extreme) the model stays finite (the domain is
    declared so that it does): the step succeeds with the package's numbers, and valid values after."""
    with FmuInstance(any_version_impact_fmu, "absurd", unzip_dir=unzipped) as fmu:
        fmu.set(**{name: value})
        fmu.do_step(step_size=1e-3)
        assert_outputs(fmu, {name: value}, name)
        fmu.set(**{name: INPUTS[name][0]})
        fmu.do_step(step_size=1e-3)
        assert_outputs(fmu, {}, name)
        assert all(status < FMI_ERROR for status, _ in fmu.messages)


# --- many instances --------------------------------------------------------------------------------
EIGHT = [  # (sphere, d, plate, t, zener_method, restitution_model)
    ("s2_tool_steel", 6.35e-3, "al_6061", 6.35e-3, 1, 1),
    ("tungsten_carbide", 4.76e-3, "al_6061", 1.0e-3, 1, 2),
    ("borosilicate_glass", 6.35e-3, "borosilicate_glass", 6.35e-2, 2, 1),
    ("brass_260", 4.76e-3, "s7_tool_steel", 3.0e-3, 3, 1),
    ("chrome_steel", 4.76e-3, "stainless_440c", 2.0e-2, 1, 2),
    ("low_carbon_steel", 6.35e-3, "al_1100_h16", 0.5e-3, 1, 1),
    ("nitinol_60", 6.35e-3, "nitinol_60", 6.35e-3, 4, 1),
    ("al_1100_h16", 6.35e-3, "s7_tool_steel", 1.0e-1, 2, 2),
]


def _eight_settings():
    out = []
    for s, d, p, t, method, model in EIGHT:
        settings = impact_fmu_parameters(r.Sphere(r.MATERIALS[s], d), r.Plate(r.MATERIALS[p], t))
        settings.update(zener_method=method, restitution_model=model)
        out.append(settings)
    return out


def _speeds(i, n=40):
    return [0.01 + 0.37 * i + 0.25 * k + 1e-3 * k * k for k in range(n)]


def test_eight_instances_interleaved_equal_one_at_a_time(any_version_impact_fmu, unzipped):
    settings = _eight_settings()
    if not runs_ode(any_version_impact_fmu):  # ode (zener_method = 4) is the Python FMU's only
        settings = [dict(s, zener_method=1) if s["zener_method"] == 4 else s for s in settings]
    n = 40

    def make(i):
        return FmuInstance(any_version_impact_fmu, f"m{i}", unzip_dir=unzipped, parameters=settings[i])

    interleaved = [[] for _ in settings]
    instances = [make(i) for i in range(len(settings))]
    try:
        for k in range(n):
            for i, fmu in enumerate(instances):
                fmu.set(v_approach=_speeds(i)[k])
                fmu.do_step(step_size=1e-3)
                interleaved[i].append(tuple(fmu.get_reals(OUTPUT_NAMES)) + tuple(fmu.get(*BOOL_OUTPUTS)))
    finally:
        for fmu in instances:
            fmu.close()

    for i in range(len(settings)):
        with make(i) as fmu:
            alone = []
            for k in range(n):
                fmu.set(v_approach=_speeds(i)[k])
                fmu.do_step(step_size=1e-3)
                alone.append(tuple(fmu.get_reals(OUTPUT_NAMES)) + tuple(fmu.get(*BOOL_OUTPUTS)))
            assert alone == interleaved[i], EIGHT[i]  # the same code on the same inputs in one process
            for k in (0, n // 2, n - 1):
                fmu.set(v_approach=_speeds(i)[k])
                assert_outputs(fmu, {**settings[i], "v_approach": _speeds(i)[k]}, EIGHT[i])
    # the eight really differ
    assert len({row[0][0] for row in interleaved}) == len(settings)


# --- next to another pythonfmu FMU ---------------------------------------------------------------
@pytest.fixture(scope="module")
def toy_fmu(tmp_path_factory):
    """ToyGain (tests/toys/toy_gain_slave.py): y = gain * sqrt(x), a different pythonfmu FMU."""
    return build_toy_fmu(tmp_path_factory.mktemp("toy"), "toy_gain_slave")


def test_runs_next_to_a_different_pythonfmu_fmu(impact_fmu, toy_fmu):
    settings = _eight_settings()[1]
    with FmuInstance(toy_fmu, "toy", parameters={"gain": 2.5}) as toy, \
            FmuInstance(impact_fmu, "impact", parameters=settings) as impact, \
            FmuInstance(toy_fmu, "toy2") as toy2:
        for k in range(50):
            x = 0.5 + 0.1 * k
            toy.set(x=x)
            impact.set(v_approach=x)
            toy2.set(x=4.0 * x)
            for fmu in (impact, toy, toy2):
                fmu.do_step(step_size=1e-2)
            assert toy.get("y", "steps") == [2.5 * math.sqrt(x), k + 1]
            assert toy2.get("y", "steps") == [1.0 * math.sqrt(4.0 * x), k + 1]  # gain 1
            assert impact.get_reals(["e"])[0] == reference({**settings, "v_approach": x}).e
        assert not any(status >= FMI_ERROR for status, _ in impact.messages + toy.messages)


# --- FMU state --------------------------------------------------------------------------------------
ALL_VARIABLES = list(INPUTS) + OUTPUT_NAMES + BOOL_OUTPUTS


def _snapshot(fmu):
    return [struct.pack("<d", x) if isinstance(x, float) else x for x in fmu.get(*ALL_VARIABLES)]


STATE_CASES = {
    "thin plate, e44, linear": {**_eight_settings()[1], "v_approach": 7.25, "zener_method": 3, "restitution_model": 2},
    "half-space (m_eff = inf)": {"plate_waves": 0, "v_approach": 1e-12},
    "no impact (v = 0)": {"v_approach": 0.0, "plate.t": 1e-4},
    "ode, odd digits": {"zener_method": 4, "zener.ode_tolerance": 3.3e-9, "v_approach": 0.1 + 0.2,
                        "sphere.nu": 0.499, "plate.nu": 0.0, "effect_tolerance": 0.0},
}


@pytest.mark.parametrize("case", list(STATE_CASES))
def test_state_get_set_and_serialize_round_trip_exactly(any_version_impact_fmu, unzipped, case):
    settings = STATE_CASES[case]
    if settings.get("zener_method") == 4 and not runs_ode(any_version_impact_fmu):
        pytest.skip("zener_method = 4 (ode) is the Python FMU's only")
    with FmuInstance(any_version_impact_fmu, "state", unzip_dir=unzipped, parameters=settings) as fmu, \
            FmuInstance(any_version_impact_fmu, "other", unzip_dir=unzipped) as other:
        fmu.do_step(0.0, 0.5)
        before = _snapshot(fmu)
        state = fmu.get_state()
        blob = fmu.serialize_state(state)
        assert 0 < len(blob) < 10_000

        fmu.set(**_eight_settings()[7], v_approach=4.0, plasticity=1)  # change everything
        fmu.do_step(0.5, 0.5)
        changed = _snapshot(fmu)
        assert changed != before

        fmu.set_state(state)  # in memory: back to t = 0.5
        assert _snapshot(fmu) == before
        fmu.do_step(0.5, 0.5)
        assert_outputs(fmu, settings, case)

        copy = other.deserialize_state(blob)  # serialized, into a different fresh instance
        other.set_state(copy)
        assert _snapshot(other) == before
        other.do_step(0.5, 0.5)
        assert_outputs(other, settings, case)
        assert other.serialize_state(copy) == blob  # and again, byte for byte
        other.free_state(copy)
        fmu.free_state(state)


# --- a long run -------------------------------------------------------------------------------------
def _rss_kib() -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
def test_one_million_steps_unchanged_results_flat_memory(any_version_impact_fmu, unzipped, record_property):
    """1e6 x (set v, step, get e and v_rebound), v cycling through four values so that every step
    evaluates the model; FmuInstance's writer, do_step and reader: raw FMI calls through fmpy's bindings
    with arrays allocated once (no per-call arrays), raising on any status above Warning."""
    speeds = [2.3, 0.05, 11.0, 0.7]
    with FmuInstance(any_version_impact_fmu, "long", unzip_dir=unzipped, parameters=_eight_settings()[0]) as fmu:
        expected = []
        for v in speeds:  # the FMU's own first answers, checked against the package within conditioning
            fmu.set(v_approach=v)
            assert_outputs(fmu, {**_eight_settings()[0], "v_approach": v})
            expected.append(tuple(fmu.get_reals(["e", "v_rebound"])))
        set_speed, do_step, get = fmu.writer("v_approach"), fmu.do_step, fmu.reader("e", "v_rebound")
        inputs = [[v] for v in speeds]
        expected = [list(pair) for pair in expected]
        h = 1e-3

        def run(first, count):
            wrong = 0
            for k in range(first, first + count):
                set_speed(inputs[k & 3])
                do_step(k * h, h)
                if get() != expected[k & 3]:
                    wrong += 1
            return wrong

        assert run(0, 50_000) == 0  # warm-up: caches, allocator pools, lazy imports
        gc.collect()
        rss0 = _rss_kib()
        t0 = time.perf_counter()
        wrong = run(50_000, 1_000_000)
        elapsed = time.perf_counter() - t0
        gc.collect()
        growth = _rss_kib() - rss0
        record_property("steps_per_second", round(1e6 / elapsed))
        record_property("rss_growth_kib", growth)
        print(f"\n1e6 steps: {1e6 / elapsed:,.0f} steps/s, RSS growth {growth} KiB")
        assert wrong == 0
        assert growth < 1024, f"resident memory grew by {growth} KiB over 1e6 steps"
        assert not any(status >= FMI_ERROR for status, _ in fmu.messages)
        assert_outputs(fmu, {**_eight_settings()[0], "v_approach": speeds[(50_000 + 1_000_000 - 1) & 3]})
