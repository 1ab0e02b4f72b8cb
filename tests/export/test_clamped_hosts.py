"""The exports to the hosts that clamp their contact force (Chrono SMC, LIGGGHTS, Yade, Modelica's ElastoGap)
checked against each host's own force law, written again in tests/export/laws_clamped.py from the host's
source and integrated there with scipy's RK45 and events (never with restitution.export.clamped):

* the exported parameter, fed to the host's clamped law, gives back the asked e within 0.5 % for e from 0.1
  to 0.98, or is refused where the host's clamped law cannot go that low (checked: its smallest parameter
  gives a higher e);
* the naive map (the host's restitution parameter = e) gives a higher e than asked: about +10 % at e = 0.5,
  about +30 % at e = 0.3, while the same law without the clamp gives e back (the formula is right, the clamp
  is what it misses);
* the fixed-step drops converge to the fine one, the snippets carry the exported numbers.
"""
from __future__ import annotations

import math
import re

import pytest

from laws_clamped import (Pair, chrono_normal_force, drop, elastogap_pushing_force, hertz_time,
                          liggghts_normal_force, yade_normal_force)
from restitution.export import chrono, clamped, elastogap, liggghts, yade

#: Bodies not in the package's presets: a 10 mm hard sphere on a soft plate, a 3 mm light one on a stiff plate.
PAIRS = (
    Pair(e=0.5, v=1.7, d=10e-3, rho=7000.0, E1=150e9, nu1=0.28, E2=45e9, nu2=0.35),
    Pair(e=0.5, v=4.2, d=3e-3, rho=3900.0, E1=370e9, nu1=0.22, E2=190e9, nu2=0.29),
)
ES = (0.1, 0.13, 0.2, 0.3, 0.5, 0.7, 0.9, 0.98)
#: The acceptance tolerance of the issue, relative.
TOLERANCE = 0.005


def with_e(pair, e):
    return Pair(**{**pair.__dict__, "e": e})


def chrono_e(params, pair, clamp=True, cr=None):
    """e of Chrono's law (laws_clamped) for the exported params: the fixed plate's own mass in m_eff."""
    m_eff = pair.m_sphere * params["plate_mass"] / (pair.m_sphere + params["plate_mass"])
    e_eff = 1.0 / ((1 - params["nu1"] ** 2) / params["E1"] + (1 - params["nu2"] ** 2) / params["E2"])
    cr = params["cr"] if cr is None else cr
    return drop(lambda x, xdot: chrono_normal_force(x, -xdot, e_eff, params["R"], m_eff, cr), pair.m_sphere,
                pair.v, hertz_time(pair), clamp)[0]


def liggghts_e(params, pair, clamp=True, cr=None):
    (y1, y2), (nu1, nu2) = params["youngsModulus"], params["poissonsRatio"]
    yeff = 1.0 / ((1 - nu1 ** 2) / y1 + (1 - nu2 ** 2) / y2)
    cr = params["coefficientRestitution"] if cr is None else cr
    return drop(lambda x, xdot: liggghts_normal_force(x, -xdot, yeff, params["R"], pair.m_sphere, cr),
                pair.m_sphere, pair.v, hertz_time(pair), clamp)[0]


def yade_e(params, pair, clamp=True, cr=None):
    (y1, y2), (nu1, nu2) = params["young"], params["poisson"]
    e_yade = y1 * y2 / ((1 - nu1 ** 2) * y2 + (1 - nu2 ** 2) * y1)
    cr = params["en"] if cr is None else cr
    return drop(lambda x, xdot: yade_normal_force(x, -xdot, e_yade, params["R"], pair.m_sphere, cr),
                pair.m_sphere, pair.v, hertz_time(pair), clamp)[0]


def elastogap_e(params, pair, d=None):
    d = params["d"] if d is None else d
    return drop(lambda x, xdot: elastogap_pushing_force(-x, -xdot, params["c"], d, params["n"]), pair.m_sphere,
                pair.v, hertz_time(pair))[0]


#: host module -> (the test's e of its law, the parameter's JSON key, the host's smallest accepted parameter)
TSUJI_HOSTS = {chrono: (chrono_e, "cr", 2.220446049250313e-16),
               liggghts: (liggghts_e, "coefficientRestitution", 0.05 * (1 + 1e-9)),
               yade: (yade_e, "en", 1e-300)}


@pytest.mark.parametrize("host", TSUJI_HOSTS, ids=lambda host: host.NAME)
@pytest.mark.parametrize("e", ES)
def test_tsuji_hosts_give_back_e(host, e):
    """Chrono, LIGGGHTS, Yade: the exported parameter gives e within 0.5 % on the host's clamped law, or the
    export refuses and the host's smallest parameter indeed gives more than e."""
    law_e, key, smallest = TSUJI_HOSTS[host]
    for pair in PAIRS:
        pair = with_e(pair, e)
        try:
            params = host.parameters(pair)
        except clamped.UnreachableRestitution as refusal:
            floor_params = {**_any_params(host, pair), key: smallest}
            floor = law_e(floor_params, pair)
            assert floor > e, f"{host.NAME} refused e = {e} but reaches {floor:.4f} ({refusal})"
            continue
        achieved = law_e(params, pair)
        assert achieved == pytest.approx(e, rel=TOLERANCE), (host.NAME, pair, params[key])


def _any_params(host, pair):
    """A valid export of the pair (at e = 0.5) whose damping parameter the caller replaces."""
    return host.parameters(with_e(pair, 0.5))


def test_floors_of_the_clamped_hosts():
    """The clamped Hertz law cannot go below e = 0.136 (Chrono, Yade) or 0.214 (LIGGGHTS' cr > 0.05): the
    exports refuse just below and answer just above, as the hosts' laws integrated here say."""
    pair = PAIRS[0]
    for host, (law_e, key, smallest) in TSUJI_HOSTS.items():
        floor = law_e({**_any_params(host, pair), key: smallest}, pair)
        assert (0.13 < floor < 0.14) if host is not liggghts else (0.21 < floor < 0.22)
        with pytest.raises(clamped.UnreachableRestitution, match="outside what"):
            host.parameters(with_e(pair, floor * 0.99))
        params = host.parameters(with_e(pair, floor * 1.01))
        assert law_e(params, pair) == pytest.approx(floor * 1.01, rel=TOLERANCE)


@pytest.mark.parametrize("e", ES)
def test_elastogap_gives_back_e(e):
    """ElastoGap: c and d exported for the pair's mass and speed give e within 0.5 % on ElastoGap's law, for
    every e (its bounded damper reaches any e); n = 1.5 and c is Hertz's constant."""
    for pair in PAIRS:
        pair = with_e(pair, e)
        params = elastogap.parameters(pair)
        assert params["n"] == 1.5
        assert params["c"] == pytest.approx(4.0 / 3.0 * pair.E_eff * math.sqrt(pair.R_sphere), rel=1e-12)
        assert elastogap_e(params, pair) == pytest.approx(e, rel=TOLERANCE)


def test_elastogap_damping_holds_at_its_speed_only():
    """A linear damper on a Hertz spring: the same d gives a higher e at a higher speed (the damping counts
    less), so d is exported per speed."""
    pair = with_e(PAIRS[0], 0.5)
    params = elastogap.parameters(pair)
    faster = Pair(**{**pair.__dict__, "v": 4.0 * pair.v})
    assert elastogap_e(params, faster) > 0.5 + 0.01


@pytest.mark.parametrize("host", TSUJI_HOSTS, ids=lambda host: host.NAME)
def test_naive_map_overshoots(host):
    """Given cr = e, the host's clamped law returns more than e: +8 to +12 % at e = 0.5, +25 to +35 % at
    e = 0.3 (the issue's about +10 % and +30 %). The same law without its clamp returns e itself to 1e-6: the
    beta formula is exact for the law the hosts would have without the clamp. The export's own report of
    the naive e agrees with the law integrated here."""
    law_e, key, _ = TSUJI_HOSTS[host]
    pair = PAIRS[1]
    for e, low, high in ((0.5, 1.08, 1.12), (0.3, 1.25, 1.35)):
        params = host.parameters(with_e(pair, e))
        naive = law_e(params, pair, cr=e)
        assert low < naive / e < high
        assert law_e(params, pair, clamp=False, cr=e) == pytest.approx(e, rel=1e-6)
        assert params["cr_naive_gives"] == pytest.approx(naive, rel=1e-6)
        assert params[key] < e  # the clamp releases early: the exact inverse asks for more damping


def test_elastogap_needs_more_damping_than_the_unbounded_law():
    """The d at which ElastoGap's law without its bound (it may pull) gives e = 0.5, found here by bisection,
    gives ElastoGap a higher e; the exported d is larger."""
    pair = with_e(PAIRS[0], 0.5)
    params = elastogap.parameters(pair)
    c, n = params["c"], params["n"]

    def unbounded_e(d):
        try:
            return drop(lambda x, xdot: c * x ** n + d * xdot, pair.m_sphere, pair.v, hertz_time(pair),
                        clamp=False)[0]
        except AssertionError:  # so much damping that the sphere creeps back and never leaves: no rebound
            return 0.0

    low, high = 0.0, params["d"] * 4.0
    for _ in range(60):  # bisection to 1e-18 of the bracket: far finer than the comparison below
        mid = 0.5 * (low + high)
        low, high = (mid, high) if unbounded_e(mid) > 0.5 else (low, mid)
    d_unbounded = 0.5 * (low + high)
    assert elastogap_e(params, pair, d=d_unbounded) > 0.5 * 1.05
    assert params["d"] > d_unbounded


@pytest.mark.parametrize("host", (chrono, liggghts, yade, elastogap), ids=lambda host: host.NAME)
def test_fixed_step_drops_converge(host):
    """simulate_drop at the host's own fixed step approaches the fine drop as the step shrinks (first order:
    a step 8 times finer leaves at most a quarter of the error), and the fine drop is the asked e."""
    pair = with_e(PAIRS[0], 0.6)
    params = host.parameters(pair)
    fine = host.simulate_drop(params, pair, None)
    assert fine["e"] == pytest.approx(0.6, rel=1e-6)
    assert fine["law"] == "published force law, integrated here"
    coarse = host.simulate_drop(params, pair, params["t_contact"] / 25)
    finer = host.simulate_drop(params, pair, params["t_contact"] / 200)
    assert abs(finer["e"] - fine["e"]) <= 0.25 * abs(coarse["e"] - fine["e"]) + 1e-9
    assert finer["t_contact"] == pytest.approx(fine["t_contact"], rel=0.02)


def _numbers_after(text, marker):
    return [float(x) for x in re.findall(re.escape(marker) + r"\s*([-+0-9.eE]+)", text)]


def test_snippets_carry_the_exported_numbers():
    """Each snippet holds the exported parameter to 9 significant digits, in the host's syntax."""
    pair = with_e(PAIRS[1], 0.45)
    p = chrono.parameters(pair)
    text = chrono.snippet(p)
    assert _numbers_after(text, "SetRestitution(") == pytest.approx([p["cr"]] * 2, rel=1e-8)
    assert "SetContactForceModel(chrono.ChSystemSMC.Hertz)" in text
    assert _numbers_after(text, "SetDefaultEffectiveCurvatureRadius(") == pytest.approx([pair.R_sphere], rel=1e-8)
    p = liggghts.parameters(pair)
    text = liggghts.snippet(p)
    assert "limitForce on" in text
    block = re.search(r"coefficientRestitution peratomtypepair 2 (.*)", text).group(1).split()
    assert [float(x) for x in block] == pytest.approx([p["coefficientRestitution"]] * 4, rel=1e-8)
    p = yade.parameters(pair)
    text = yade.snippet(p)
    assert _numbers_after(text, "MindlinPhys(en=") == pytest.approx([p["en"]], rel=1e-8)
    assert "hertzian=True" in text
    p = elastogap.parameters(pair)
    text = elastogap.snippet(p)
    assert _numbers_after(text, "(c=") == pytest.approx([p["c"]], rel=1e-8)
    assert _numbers_after(text, " d=") == pytest.approx([p["d"]], rel=1e-8)
    assert "n=1.5" in text and "s_rel0=0" in text


@pytest.mark.parametrize("v", (0.3, 3.0))
def test_exports_of_impact_cases(v):
    """From the model's own impact (restitution.export.hosts.export_case, the command's path) for bodies that
    are no preset: every clamped host's export gives the model's e within 0.5 % on the host's law, where the
    host reaches it."""
    hosts = pytest.importorskip("restitution.export.hosts", reason="restitution.export.hosts (the export command's "
                                "case builder) is not in this tree")
    from restitution import Material

    sphere = Material("test sphere", E=160e9, nu=0.27, Sy=900e6, rho=7400.0)
    plate = Material("test plate", E=48e9, nu=0.34, Sy=160e6, rho=2650.0)
    case = hosts.export_case(v, sphere, plate, d=5e-3, t=6e-3)
    assert 0.4 < case.e < 0.7  # plasticity and plate waves both at work
    pair = Pair(e=case.e, v=v, d=5e-3, rho=7400.0, E1=160e9, nu1=0.27, E2=48e9, nu2=0.34)
    assert case.m_sphere == pytest.approx(pair.m_sphere, rel=1e-9) and case.E_eff == pytest.approx(pair.E_eff)
    for host, (law_e, _key, _smallest) in TSUJI_HOSTS.items():
        assert law_e(host.parameters(case), pair) == pytest.approx(case.e, rel=TOLERANCE), host.NAME
    assert elastogap_e(elastogap.parameters(case), pair) == pytest.approx(case.e, rel=TOLERANCE)
