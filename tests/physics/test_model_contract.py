"""The contract of the public API around the physics: what a caller gets back (types, shapes,
dtypes, ownership of arrays), and what a mistake tells them (the message names the option or
parameter, its unit and the allowed values). These are properties, not numbers of the model;
the numbers are checked against independent references elsewhere (test_paper_*.py)."""
import math
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest

import restitution as r
from restitution import jgm, zener, zener_exact
from restitution.model import ZENER_SLOPE_BOUND
from restitution.materials import MATERIALS, TABLE4_CASES, Material, Plate, Sphere, table4_case
from restitution.model import PARAMETERS, validate_parameters

S2, AL = MATERIALS["s2_tool_steel"], MATERIALS["al_6061"]
PARAMS = dict(**Sphere(S2, 6.35e-3).params(), **Plate(AL, 6.35e-3).params())
FIELDS = tuple(r.ImpactResult.__dataclass_fields__)
FLAGS = ("plasticity_used", "plate_waves_used", "lambda_in_range", "vstar_in_range", "e_negative", "contact_ends",
         "concurrent", "edge_clear")


# --- options: the message names the option and lists what is allowed

@pytest.mark.parametrize("option,bad", [
    ("plasticity", "bogus"), ("plasticity", 3), ("plasticity", -1), ("plasticity", True), ("plasticity", 1.0),
    ("plate_waves", "bogus"), ("plate_waves", 3), ("plate_waves", None),
    ("restitution_model", "e46"), ("zener_method", "EXACT"),
])
def test_bad_option_is_named_with_its_allowed_values(option, bad):
    with pytest.raises(ValueError) as err:
        r.impact(2.0, **PARAMS, **{option: bad})
    text = str(err.value)
    assert text.startswith(f"{option} = {bad!r}"), text
    allowed = {"plasticity": "off", "plate_waves": "off", "restitution_model": "e45", "zener_method": "paper_fit"}
    assert allowed[option] in text


@pytest.mark.parametrize("option,bad,allowed", [("effect_tolerance", -1e-3, ">= 0"), ("ode_rtol", 0.0, "> 0"),
                                                ("ode_rtol", math.nan, "> 0")])
def test_bad_numeric_option_is_named(option, bad, allowed):
    with pytest.raises(ValueError) as err:
        r.impact(2.0, **PARAMS, **{option: bad})
    assert str(err.value).startswith(f"{option} = {bad!r}") and allowed in str(err.value)


@pytest.mark.parametrize("code,word", [(0, "off"), (1, "on"), (2, "auto"), (np.int64(1), "on")])
def test_effect_modes_accept_codes_and_words_alike(code, word):
    by_code = r.impact(3.0, **PARAMS, plasticity=code, plate_waves=code)
    by_word = r.impact(3.0, **PARAMS, plasticity=word, plate_waves=word)
    assert by_code == by_word


def test_speed_message_carries_its_unit_and_parameters_theirs():
    with pytest.raises(ValueError, match=r"^v_approach = -1\.0 m/s is outside"):
        r.impact(-1.0, **PARAMS)
    units = {name: unit for name, unit, _ in PARAMETERS}
    for name, unit, kind in PARAMETERS:
        bad = dict(PARAMS, **{name: -1.0})
        label = name.replace("_", ".", 1)
        suffix = "" if kind == "poisson" else f" {unit}"
        for call in (lambda: r.impact(1.0, **bad), lambda: validate_parameters(**bad)):
            with pytest.raises(ValueError) as err:
                call()
            assert str(err.value).startswith(f"{label} = -1.0{suffix} is outside"), (str(err.value), units[name])


# --- materials: messages name the material and property, with its unit

@pytest.mark.parametrize("prop,unit", [("E", " Pa"), ("nu", ""), ("Sy", " Pa"), ("rho", " kg/m3")])
def test_bad_material_property_is_named_with_unit(prop, unit):
    values = dict(E=200e9, nu=0.3, Sy=1e9, rho=7800.0)
    values[prop] = -1.0
    with pytest.raises(ValueError) as err:
        Material("steel x", **values)
    assert str(err.value).startswith(f"steel x.{prop} = -1.0{unit} is outside"), str(err.value)


@pytest.mark.parametrize("make,label", [(lambda: Sphere(S2, 0.0), "sphere.d"), (lambda: Plate(AL, -1e-3), "plate.t")])
def test_bad_geometry_is_named_in_metres(make, label):
    with pytest.raises(ValueError) as err:
        make()
    assert str(err.value).startswith(f"{label} = ") and " m is outside" in str(err.value)


@pytest.mark.parametrize("case", ["C1", "A5", "A0", "a", "", "B12"])
def test_bad_table4_case_lists_the_cases(case):
    with pytest.raises(ValueError, match=r"Table 4 case = .* is not one of A1-A4, B1-B4"):
        table4_case(case)


@pytest.mark.parametrize("case", TABLE4_CASES)
def test_table4_materials_are_named_and_sourced(case):
    sphere, plate = table4_case(case)
    assert sphere.name == f"Table 4 {case} sphere" and plate.name == f"Table 4 {case} plate"
    assert "Table 4" in sphere.source and "Table 4" in plate.source
    assert table4_case(case.lower()) == (sphere, plate)


def test_every_preset_says_where_its_values_come_from():
    for key in MATERIALS:
        assert MATERIALS[key].source.strip(), key


# --- what comes back: Python floats for one impact, owned float/bool arrays otherwise

def test_one_impact_in_python_floats_gives_python_floats_and_bools():
    res = r.impact(2.3, **PARAMS)
    for name in FIELDS:
        value = getattr(res, name)
        assert value.__class__ is (bool if name in FLAGS else float), (name, type(value))


@pytest.mark.parametrize("name", ["v"] + [name for name, _, _ in PARAMETERS])
@pytest.mark.parametrize("kind", ["int", "numpy scalar", "numpy int", "Fraction"])
def test_other_real_scalars_give_the_same_python_floats(name, kind):
    args = dict(PARAMS, v=2.0)
    value = args[name]
    converted = {"int": lambda x: int(x) if float(x).is_integer() else x, "numpy scalar": np.float64,
                 "numpy int": lambda x: np.int64(x) if float(x).is_integer() else np.float32(x),
                 "Fraction": Fraction}[kind](value)
    res = r.impact(**dict(args, **{name: converted}))
    if kind == "numpy int" and not float(value).is_integer():  # float32: its own value, same types
        res32 = r.impact(**dict(args, **{name: float(converted)}))
        assert res == res32
    else:
        assert res == r.impact(**args)
    assert all(getattr(res, f).__class__ is (bool if f in FLAGS else float) for f in FIELDS)


@pytest.mark.parametrize("name", ["v"] + [name for name, _, _ in PARAMETERS])
def test_one_array_input_gives_arrays_of_the_broadcast_shape(name):
    args = dict(PARAMS, v=2.0)
    res = r.impact(**dict(args, **{name: np.full((2, 1), args[name])}), **{})
    one = r.impact(**args)
    for f in FIELDS:
        value = getattr(res, f)
        assert value.__class__ is np.ndarray and value.shape == (2, 1), f
        assert value.dtype == (np.bool_ if f in FLAGS else np.float64), (f, value.dtype)
        assert np.all(value == getattr(one, f)) or (f == "m_eff" and np.all(np.isinf(value))), f


def test_integer_and_object_arrays_are_read_as_floats():
    v = np.array([1, 2, 4])
    res = r.impact(v, **dict(PARAMS, plate_rho=np.array([2700, 2700, 2700])))
    ref = r.impact(v.astype(float), **PARAMS)
    for f in FIELDS:
        assert getattr(res, f).dtype == getattr(ref, f).dtype and np.array_equal(getattr(res, f), getattr(ref, f)), f
    obj = r.impact(np.array([Fraction(1), Fraction(2), Fraction(4)], dtype=object), **PARAMS)
    assert np.array_equal(obj.e, ref.e) and obj.e.dtype == np.float64


@pytest.mark.parametrize("plasticity", ["on", "off", "auto"])
@pytest.mark.parametrize("plate_waves", ["on", "off", "auto"])
def test_result_arrays_are_owned_and_never_alias_inputs_or_each_other(plasticity, plate_waves):
    v = np.array([0.0, 1e-9, 0.5, 3.0, 40.0])
    t = np.full(5, 6.35e-3)
    res = r.impact(v, **dict(PARAMS, plate_t=t), plasticity=plasticity, plate_waves=plate_waves)
    arrays = [getattr(res, f) for f in FIELDS]
    for i, a in enumerate(arrays):
        assert a.shape == (5,) and a.flags.writeable, FIELDS[i]
        assert not np.shares_memory(a, v) and not np.shares_memory(a, t), FIELDS[i]
        for j in range(i):
            assert not np.shares_memory(a, arrays[j]), (FIELDS[i], FIELDS[j])
    before = res.e.copy()
    res.e[:] = -5.0  # the caller may write into what it got: nothing else changes
    assert np.all(v == [0.0, 1e-9, 0.5, 3.0, 40.0]) and np.all(res.v_rebound == before * v)


def test_as_dict_has_every_field_in_order_then_valid():
    for res in (r.impact(2.0, **PARAMS), r.impact(np.array([2.0, 3e4]), **PARAMS)):
        d = res.as_dict()
        assert tuple(d) == FIELDS + ("valid",)
        assert all(d[f] is getattr(res, f) for f in FIELDS)
        assert np.array_equal(d["valid"], np.logical_and(res.lambda_in_range, res.vstar_in_range))



def _shown(text: str, label: str) -> str:
    import re

    match = re.search(rf"(?<![\w*]){re.escape(label)} = (\S+?)[,)\s]", text + " ")
    assert match, f"{label} not shown in:\n{text}"
    return match.group(1)


@pytest.mark.parametrize("options", [{}, {"zener_method": "linear"}], ids=["exact", "linear"])
@pytest.mark.parametrize("v", [0.0, 2.0, 3e4], ids=["at_rest", "usual", "beyond_fit"])
def test_printing_one_result_shows_the_answer_and_every_flag(v, options):
    """What a user sees without looking for it: e, its two parts, the rebound speed and the validity
    flags (with the condition each checks), each the result's own value to the 4 digits printed."""
    res = r.impact(v, **{**PARAMS, "plate_t": 1e-4}, **options)
    text = repr(res)
    assert text == str(res) and text.startswith("ImpactResult: ")
    for label in ("e", "e_ep", "e_ze", "v_rebound", "V*", "V_c", "lambda", "t_contact"):
        field = {"V*": "V_star", "lambda": "lam"}.get(label, label)
        assert float(_shown(text, label)) == pytest.approx(getattr(res, field), rel=5e-4, abs=0.0), label
    for flag in ("valid", "plasticity_used", "plate_waves_used", "e_negative", "contact_ends"):
        assert _shown(text, flag).rstrip(":") == str(getattr(res, flag)), flag
    assert f"(lambda_in_range) {res.lambda_in_range}" in text and f"(vstar_in_range) {res.vstar_in_range}" in text


def test_printing_an_array_result_counts_each_flag():
    v = np.array([[0.0, 2.0, 3e4], [1.0, 5.0, np.nextafter(0.0, 1.0)]])
    res = r.impact(v, **PARAMS)
    text = repr(res)
    assert text.startswith(f"ImpactResult of 6 impacts, shape (2, 3): e in [{res.e.min():.4g}, {res.e.max():.4g}]")
    assert f"valid at {np.count_nonzero(res.valid)} of 6" in text
    for flag in ("lambda_in_range", "vstar_in_range", "plasticity_used", "plate_waves_used", "e_negative",
                 "contact_ends"):
        assert f"{flag} {np.count_nonzero(getattr(res, flag))}" in text, flag

# --- the Zener back ends: the same contract for every way a lambda can arrive

@pytest.mark.parametrize("lam", [0, 1, 100, np.float32(0.5), np.int64(3), Fraction(1, 2), Decimal("0.5"), 150, 1e3])
def test_zener_exact_takes_any_real_scalar(lam):
    e, d, tau0 = zener_exact.zener_exact_solution(lam)
    ref = zener_exact.zener_exact_solution(np.array([float(lam)]))
    assert all(isinstance(x, float) for x in (e, d, tau0))
    # the same value as the array path, to a few ulps (numpy's and libm's log/pow may differ in the last bit)
    assert np.allclose([e, d, tau0], [x[0] for x in ref], rtol=8e-16, atol=0.0)


@pytest.mark.parametrize("lam", [-1e-300, -1.0, math.nan, math.inf, "x", 1 + 1j, np.complex128(1.0)])
def test_zener_exact_names_a_bad_lambda(lam):
    with pytest.raises(ValueError) as err:
        zener_exact.zener_exact_solution(lam)
    text = str(err.value)
    assert text.startswith("lambda must be finite and >= 0 (allowed range [0, inf)); got lambda=")
    shown = float(lam) if isinstance(lam, float) else lam
    assert text.endswith(f"got lambda={shown!r}"), text


def test_zener_exact_array_error_points_at_the_bad_element():
    with pytest.raises(ValueError, match=r"got lambda=-0\.5 \(at index \(1, 0\)\)$"):
        zener_exact.zener_exact_solution(np.array([[0.5], [-0.5], [1.0]]))
    with pytest.raises(ValueError, match=r"got lambda=-0\.5 \(at index \(1,\)\)$"):
        zener_exact.zener_exact_solution(np.array([0.0, -0.5]))
    with pytest.raises(ValueError, match=r"got lambda=nan$"):
        zener_exact.zener_exact_solution(np.array(math.nan))
    assert [x.shape for x in zener_exact.zener_exact_solution(np.zeros((0, 3)))] == [(0, 3)] * 3
    zero_d = zener_exact.zener_exact_solution(np.array(0.25))
    assert all(x.__class__ is np.ndarray and x.shape == () for x in zero_d)
    e, d, tau0 = zener_exact.zener_exact_solution([0.0, 0.25, 1e3])
    assert e.dtype == np.float64 and e[0] == 1.0 and d[0] == 0.0


def test_zener_exact_array_of_only_large_lambda_raises_no_floating_point_error():
    """e_ze ~ 0.679 lambda^-5 underflows to 0 and tau0 ~ 5 lambda ln lambda overflows to inf, silently, as on
    the float path (Python's float power underflows to 0 without an error)."""
    lams = [1e3, 1e70, 1e300, 1e306]
    with np.errstate(all="raise"):
        e, d, tau0 = zener_exact.zener_exact_solution(np.array(lams))
    assert all(x.dtype == np.float64 for x in (e, d, tau0))
    assert e[0] > 0.0 and e[2] == 0.0 and d[2] == 1.0 and np.all(np.isfinite(tau0[:3])) and tau0[3] == math.inf
    for i, lam in enumerate(lams[:3]):
        assert (e[i], d[i]) == pytest.approx(zener_exact.zener_exact_solution(lam)[:2], rel=8e-16, abs=0.0)


def test_zener_exact_takes_any_array_like():
    e, d, tau0 = zener_exact.zener_exact_solution(range(3))
    assert e.__class__ is np.ndarray and e.shape == (3,) and e[0] == 1.0


def test_unchecked_calls_still_read_exact_numbers_as_floats():
    """validate=False skips the checks, not the conversion to float arrays."""
    ref = r.impact(np.array([2.0, 4.0]), **PARAMS)
    exact = {name: np.array([Fraction(value)] * 2, dtype=object) for name, value in PARAMS.items()}
    got = r.impact(np.array([Fraction(2), Fraction(4)], dtype=object), **exact, validate=False)
    for f in FIELDS:
        assert getattr(got, f).dtype == getattr(ref, f).dtype
        assert np.allclose(getattr(got, f), getattr(ref, f), rtol=1e-15, atol=0.0), f


def test_zener_exact_reads_a_list_of_exact_numbers_as_floats():
    e, d, tau0 = zener_exact.zener_exact_solution([Fraction(1, 2), Fraction(3, 2)])
    assert all(x.dtype == np.float64 for x in (e, d, tau0))
    assert e.tolist() == [zener_exact.zener_exact_solution(0.5)[0], zener_exact.zener_exact_solution(1.5)[0]]


@pytest.mark.parametrize("method", r.ZENER_METHODS if hasattr(r, "ZENER_METHODS") else zener.ZENER_METHODS)
def test_zener_methods_default_to_exact_and_name_unknown_ones(method):
    assert zener.zener_solution(0.3) == zener.zener_solution(0.3, "exact")
    assert zener.zener_restitution(0.3) == zener.zener_restitution(0.3, "exact")
    with pytest.raises(ValueError, match=r"^zener_method = 'nope' is not one of"):
        zener.zener_solution(0.3, "nope")
    e, d, tau0 = zener.zener_solution(np.array([0.0, 0.3]), method)
    assert e.dtype == np.float64 and e.shape == (2,)


def test_ode_defaults_to_a_tight_tolerance():
    """Without an rtol the ode method solves to 1e-10: it agrees with the exact method (itself
    within 1e-8 of independent solves, test_zener_exact.py) to 1e-8, scalar and array."""
    exact = zener.zener_solution(0.7, "exact")
    for got in (zener.zener_ode(0.7), zener.zener_restitution(0.7, "ode"), zener.zener_solution(0.7, "ode")[::2],
                tuple(x[0] for x in zener.zener_ode(np.array([0.7]))),
                tuple(float(x[0]) for x in zener.zener_ode(np.array([Fraction(7, 10)], dtype=object)))):
        assert got[0] == pytest.approx(exact[0], rel=1e-8) and got[1] == pytest.approx(exact[2], rel=1e-8)


def test_ode_rtol_reaches_the_solver_on_every_path():
    """A loose ode_rtol gives a different (still close) answer than the default on the scalar path, the
    all-needed array path and the masked array path (plate_waves="auto" skipping a tiny lambda)."""
    v = np.array([1e-30, 3.0])  # the first one's lambda is below the auto threshold
    loose = dict(zener_method="ode", ode_rtol=1e-3)
    tight = dict(zener_method="ode")
    cases = [(3.0, {}), (np.array([3.0, 3.0]), {}), (v, {})]
    for speed, _ in cases:
        a = r.impact(speed, **PARAMS, **loose)
        b = r.impact(speed, **PARAMS, **tight)
        e_a, e_b = np.ravel(a.e_ze)[-1], np.ravel(b.e_ze)[-1]
        assert e_a != e_b and abs(e_a - e_b) <= 1e-2, (speed, e_a, e_b)
    masked = r.impact(v, **PARAMS, **loose)
    assert masked.plate_waves_used.tolist() == [False, True]


def test_validity_flags_include_their_bounds():
    """lambda <= 1.5 and V* <= 1000 are inside the studied / fitted ranges, the next float is not."""
    assert zener.lambda_in_studied_range(1.5) and not zener.lambda_in_studied_range(math.nextafter(1.5, 2))
    assert jgm.vstar_in_fit_range(1000.0) and not jgm.vstar_in_fit_range(math.nextafter(1000.0, 2e3))
    assert zener.lambda_in_studied_range(np.array([1.5, 1.6])).tolist() == [True, False]


def test_auto_skips_an_effect_only_strictly_below_the_tolerance():
    """plasticity/plate_waves="auto" drop an effect whose contribution is *below* effect_tolerance; at a
    tolerance equal to the contribution (an exact tie, built from the model's own e_ep and lambda) it stays."""
    on = r.impact(3.0, **PARAMS, plasticity="on", plate_waves="on")
    tol_ep = 1.0 - on.e_ep
    tied = r.impact(3.0, **PARAMS, plasticity="auto", plate_waves="on", effect_tolerance=tol_ep)
    assert tied.plasticity_used and tied.e_ep == on.e_ep
    above = r.impact(3.0, **PARAMS, plasticity="auto", plate_waves="on", effect_tolerance=math.nextafter(tol_ep, 1))
    assert not above.plasticity_used and above.e_ep == 1.0
    tol_ze = ZENER_SLOPE_BOUND * on.lam
    tied = r.impact(3.0, **PARAMS, plasticity="on", plate_waves="auto", effect_tolerance=tol_ze)
    assert tied.plate_waves_used and tied.e_ze == on.e_ze
    above = r.impact(3.0, **PARAMS, plasticity="on", plate_waves="auto", effect_tolerance=math.nextafter(tol_ze, 1))
    assert not above.plate_waves_used and above.e_ze == 1.0


def test_two_array_inputs_broadcast_together():
    res = r.impact(np.array([0.5, 3.0, 40.0, 0.0, 1e3]), **dict(PARAMS, plate_E=np.array([[70e9], [200e9], [3e9]])))
    for f in FIELDS:
        value = getattr(res, f)
        assert value.shape == (3, 5) and value.dtype == (np.bool_ if f in FLAGS else np.float64), f
    one = r.impact(40.0, **dict(PARAMS, plate_E=200e9))
    assert res.e[1, 2] == pytest.approx(one.e, rel=1e-14)


def test_zener_restitution_passes_its_tolerance_on():
    loose = zener.zener_restitution(0.7, "ode", 1e-3)
    tight = zener.zener_restitution(0.7, "ode")
    assert loose != tight and loose == pytest.approx(tight, rel=1e-2)


@pytest.mark.parametrize("typo,suggested", [("al6061", "al_6061"), ("s2 tool steel", "s2_tool_steel"),
                                            ("aluminum", "al_1100_h16"), ("Brass", "brass_260")])
def test_an_unknown_material_suggests_the_close_ones(typo, suggested):
    with pytest.raises(KeyError) as err:
        MATERIALS[typo]
    text = str(err.value)
    assert f"unknown material {typo!r} (did you mean " in text and repr(suggested) in text
    assert text.rstrip("\"'").endswith(", ".join(sorted(MATERIALS)))


def test_no_suggestion_when_nothing_is_close():
    from restitution.materials import suggest_material

    assert suggest_material("unobtainium", MATERIALS) == ""
    assert suggest_material("xy", ["al_6061"]) == ""
    assert suggest_material("al_6016", ["al_6061", "s2_tool_steel"]) == " (did you mean 'al_6061'?)"
    assert suggest_material("AL_6016", ["al_6061", "al_6063", "s2"]) == " (did you mean 'al_6063' or 'al_6061'?)"  # closest first
    with pytest.raises(KeyError, match=r"unknown material 'unobtainium'; known: "):
        MATERIALS["unobtainium"]


def test_suggestions_are_few_and_closest_first():
    """suggest_material's contract (its docstring): at most two names close in spelling, closest first; else at
    most three presets whose full name has every word of three letters or more, words split at underscores."""
    from restitution.materials import suggest_material

    # 'al_110' is close in spelling to three keys (al_110_h16, al_1100_h16, al_6061): two are offered
    assert suggest_material("al_110", MATERIALS) == " (did you mean 'al_110_h16' or 'al_1100_h16'?)"
    # no key is close in spelling; the words, split at the underscore, name tungsten carbide in reverse order
    assert suggest_material("carbide_tungsten", MATERIALS) == " (did you mean 'tungsten_carbide'?)"
    # "440" (three letters) counts: only the 440C stainless steel, not every steel
    assert suggest_material("steel 440", MATERIALS) == " (did you mean 'stainless_440c'?)"
    # seven presets are steels by name (five of the paper's, stainless 304 and 316): three are offered, each a steel
    text = suggest_material("steel", MATERIALS)
    offered = text.removeprefix(" (did you mean ").removesuffix("?)").split(" or ")
    steels = [key for key, mat in MATERIALS.items() if "steel" in mat.name.lower()]
    assert len(steels) == 7 and len(offered) == 3 and all(o.strip("'") in steels for o in offered), text


def test_one_impact_in_floats_reuses_the_material_step():
    """The material-only step (Eqs. 1-6) of a float impact is memoised: a second impact with the same
    materials at another speed does not recompute it (what a co-simulation pays per step). The count is
    taken after the first impact: whether that one found the step cached depends on what ran before in
    the process (a mutation tool forks its test runs from a process that has run them already)."""
    from restitution.model import _material_terms_cached

    first = r.impact(1.0, **PARAMS)
    hits = _material_terms_cached.cache_info().hits
    second = r.impact(2.0, **PARAMS)
    assert _material_terms_cached.cache_info().hits == hits + 1
    assert first.V_c == second.V_c and first.eps_y == second.eps_y


def test_plate_wave_speed_is_the_thin_plate_longitudinal_speed():
    """The plate wave speed of Eq. (12), sqrt(E' / rho) with E' = E / (1 - nu^2), is the thin-plate
    longitudinal wave speed: ~5.35 km/s in aluminium and ~5.4 km/s in steel (Graff, Wave Motion in Elastic
    Solids, Sec. 8.1, with handbook moduli), to 1 %; it scales as sqrt(E / rho) and grows with nu."""
    assert zener.plate_wave_speed(69e9, 0.33, 2700.0) == pytest.approx(5350.0, rel=1e-2)
    assert zener.plate_wave_speed(207e9, 0.30, 7861.0) == pytest.approx(5400.0, rel=1e-2)
    base = zener.plate_wave_speed(69e9, 0.33, 2700.0)
    assert zener.plate_wave_speed(4 * 69e9, 0.33, 2700.0) == pytest.approx(2 * base, rel=1e-15)
    assert zener.plate_wave_speed(69e9, 0.33, 4 * 2700.0) == pytest.approx(base / 2, rel=1e-15)
    bar = zener.plate_wave_speed(69e9, 0.0, 2700.0)  # nu = 0: the bar speed sqrt(E / rho)
    assert bar == pytest.approx(math.sqrt(69e9 / 2700.0), rel=1e-15) and bar < base
    arr = zener.plate_wave_speed(np.array([69e9, 207e9]), np.array([0.33, 0.30]), np.array([2700.0, 7861.0]))
    assert arr.shape == (2,) and arr[0] == pytest.approx(base, rel=1e-15)
