"""SpherePlateImpact's documentation beyond its interface table: the equations, what each output is,
the assumptions and the validity (``documentation/index.html`` of every SpherePlateImpact FMU,
written by :func:`restitution.fmu.describe.documentation.index_html`). The facts are those of docs/model.md ("What
the FMU computes") and of the docstrings of :mod:`restitution.jgm`, :mod:`restitution.zener` and
:mod:`restitution.fusion`; plain text, variable names between backticks."""
from __future__ import annotations

from ..text import Rows, Section

EQUATIONS = Rows(
    ("step", "equation", "Green (2022)", "FMU variables"),
    (
        ("effective modulus", "E' = E'_a E'_b / (E'_a + E'_b), with E'_i = E_i / (1 \u2212 \u03bd_i\u00b2)",
         "Eq. (1)", ""),
        ("yield onset", "C(\u03bd) = 1.295 exp(0.736 \u03bd); C S_y = min[C(\u03bd_a) S_ya, C(\u03bd_b) S_yb]: the "
         "body with the smaller value yields first", "Eq. (2)", ""),
        ("yield strain", "\u03b5_y = S_y / E', S_y of the body that yields first", "Eq. (3)", ""),
        ("critical interference, load and velocity", "\u03c9_c = (\u03c0 C S_y / (2 E'))\u00b2 R, "
         "P_c = 4/3 (R/E')\u00b2 (\u03c0/2 C S_y)\u00b3, V_c = \u221a(4 \u03c9_c P_c / (5 m_a)), with R = d/2 and "
         "m_a = \u03c1_a \u03c0 d\u00b3/6 (V_c does not depend on d)", "Eqs. (4)\u2013(6)", "`jgm.V_c`, `sphere.m`"),
        ("elastoplastic COR", "V* = v / V_c; for V* > 1, e45 = 1 \u2212 0.0361 \u03b5_y^\u22120.114 ln V* "
         "(V* \u2212 1)^(9.5 \u03b5_y) (`restitution_model` = 1) or e44 (= 2); e_ep = 1 for V* \u2264 1",
         "Eqs. (7), (8)", "`jgm.e`, `jgm.V_star`"),
        ("Zener's parameter", "\u03bb = \u03c0^(3/5)/\u221a3 ((d/2)/t)\u00b2 (v/v')^(1/5) (\u03c1_a/\u03c1_b)^(3/5) "
         "(E'_a/(E'_a + E'_b))^(2/5), with v' = \u221a(E'_b/\u03c1_b) the plate's wave speed", "Eq. (12)",
         "`zener.lambda`"),
        ("Zener's ODE", "\u03c3'' + (1 + \u03bb d/d\u03c4) \u03c3^(3/2) = 0, \u03c3(0) = 0, \u03c3'(0) = 1; the "
         "sphere leaves at the first return \u03c3(\u03c4\u2080) = 0, and e_ze = \u2212\u03c3'(\u03c4\u2080)",
         "Eqs. (10), (11)", "`zener.e`, `zener.tau0`"),
        ("the paper's fit of it", "e_ze = exp(\u22121.68374 \u03bb), \u03c4\u2080 = 3.215 exp(0.318 \u03bb^(3/2)) "
         "(`zener_method` = 2)", "Eqs. (13), (13a)", "`zener.e`, `zener.tau0`"),
        ("contact time", "t_contact = T \u03c4\u2080, T = (m_a / (k v^(1/2)))^(2/5), "
         "k = 4/3 (d/2)^(1/2) E' (Hertz: F = k s^(3/2))", "Eq. (9)", "`zener.t_contact`"),
        ("equivalent plate mass", "m_b = (1 + e_ze) m_a / (1 \u2212 e_ze), published as the finite ratio "
         "m_a/m_b = (1 \u2212 e_ze)/(1 + e_ze)", "Eq. (19)", "`plate.mass_ratio`"),
        ("apparent COR", "e = (e_ep + e_ze + e_ep e_ze \u2212 1) / 2", "Eq. (20)", "`e`"),
        ("velocities after impact", "v_a2 = \u2212e v, v_b2 = (1 + e_ep)(1 \u2212 e_ze)/2 \u00b7 v, positive "
         "along the approach, the plate at rest before", "Eq. (17)", "`v_rebound`, `plate.v_after`"),
    ))

DOCUMENTATION = (
    Section("What it computes", (
        "A sphere (subscript a) hits a plate of finite thickness (subscript b) at the normal approach speed v, "
        "`v_approach`. Two losses act during that one contact: elastoplastic deformation, the Jackson\u2013Green\u2013"
        "Marghitu (JGM) model, Eqs. (1)\u2013(8), and elastic waves carried away into the plate, Zener's model, "
        "Eqs. (9)\u2013(13a). I. Green (2022) fuses them through an equivalent plate mass into the apparent "
        "coefficient of restitution (COR), Eq. (20): e = (e_ep + e_ze + e_ep e_ze \u2212 1)/2, where e_ep is the "
        "elastoplastic COR and e_ze Zener's. With no plasticity (e_ep = 1) e is e_ze; on a half-space "
        "(e_ze = 1) it is e_ep.",
        EQUATIONS,
        "What the outputs are:",
        (
            "`e`: the apparent COR, the sphere's rebound speed over its approach speed; `v_rebound` = e v. A "
            "negative e is a result, not an error: the sphere keeps moving with the plate after the impact "
            "(thin plates, where e_ze is small), and `e_negative` says so.",
            "`jgm.e`, `jgm.V_c`, `jgm.V_star`: the elastoplastic COR e_ep, the speed at which yielding begins and "
            "the normalised speed V* = v/V_c.",
            "`zener.e`, `zener.lambda`, `zener.tau0`, `zener.t_contact`: Zener's COR e_ze, his inelasticity "
            "parameter \u03bb, the dimensionless contact time \u03c4\u2080 and the contact duration in seconds.",
            "`plate.mass_ratio`, `plate.v_after`, `sphere.m`: the sphere's mass over the equivalent plate mass "
            "(0 for a half-space, where m_b is infinite), the plate's velocity after the impact and the sphere's "
            "mass m_a.",
            "`valid`, `jgm.in_range`, `zener.in_range`: inside both models' validated ranges (below); "
            "`effects.plasticity`, `effects.plate_waves`: which effects were applied; `zener.contact_ends`: the "
            "sphere leaves the plate after a finite time (false only for the linear method at \u03bb \u2265 2).",
            "`sphere.used.*`, `plate.used.*`: the material properties the model used, a preset's where "
            "`sphere.material` or `plate.material` names one.",
            "`monitor.wave_delay`, `monitor.concurrent`: Zener's contact time over its half-space value, "
            "\u03c4\u2080(\u03bb)/\u03c4\u2080(0), and whether it is at most 1.8136, its value at \u03bb = 1.5 "
            "(below).",
            "`monitor.edge_echo`, `monitor.edge_clear`: the time a P-wave takes to come back from the plate's "
            "nearest edge, `plate.edge_distance` away, over the contact time, and whether it is at least 1 "
            "(below).",
        ),
        "Zener's COR and contact time come from `zener_method`: 1 = exact interpolates a table of the ODE's "
        "solution computed offline (relative error \u2264 1e-8 for \u03bb in [0, 100], the verified asymptote "
        "e_ze = 0.6793 \u03bb^\u22125 beyond); 2 = paper_fit is Eqs. (13) and (13a) as published; 3 = linear is "
        "the closed form of the linearised ODE, Eq. (22); 4 = ode integrates Eq. (10) at every evaluation (the "
        "pythonfmu FMU only). `plasticity` and `plate_waves` switch each effect: 0 = off (e_ep = 1, or e_ze = 1: "
        "the plate a half-space), 1 = on, 2 = auto, which skips the effect where its change of e is below "
        "`effect_tolerance`.",
        "Every output is finite for every input in the declared ranges. Where the physics is infinite the FMU "
        "publishes a finite value: the equivalent plate mass of a half-space as `plate.mass_ratio` = 0, and the "
        "linear method's contact at \u03bb \u2265 2, which never ends, as `zener.contact_ends` = false with "
        "`zener.tau0` = `zener.t_contact` = 0.",
        "Where the code departs from the printed paper (docs/paper_departures.md in the source distribution): "
        "Eq. (7)'s second branch is the reconstruction ((V* \u2212 60)/940)^2.366; where the JGM fits fall below 0 "
        "(large \u03b5_y, or beyond their range) e_ep is floored at 0; the paper fit's \u03c4\u2080 is held at its "
        "value for \u03bb \u2248 169 beyond, where exp overflows.",
    )),
    Section("Using it", (
        "Every output follows the inputs and parameters directly (direct feedthrough): set `v_approach` to the "
        "approach speed of an impact and read `e`, before any step or after one. The FMU keeps nothing from "
        "one impact to the next; a co-simulation step only moves its time on. With BouncingBall.fmu: connect "
        "`BouncingBall.v_approach` to `v_approach` and `e` to `BouncingBall.e`, and give both the same sphere.",
    )),
    Section("Model exchange", (
        "SpherePlateImpact has no continuous states and no event indicators: its outputs follow its inputs "
        "(direct feedthrough) in every mode. Initialization ends in event mode.",
    ), model_exchange=True),
    Section("Assumptions and validity", (
        (
            "A normal impact of a sphere on a flat plate at rest; the sphere's approach speed is `v_approach`.",
            "Elastic-perfectly plastic bodies (JGM) in Hertzian elastic contact (Zener, F = k s^(3/2)); the sphere "
            "is on the plate, so R = d/2.",
            "The plate is wide enough that the waves it carries away do not come back from its edges while the "
            "sphere is in contact (Zener's \u201clarge plates\u201d): its lateral size does not enter the model, "
            "only its thickness `plate.t`. The monitor: set `plate.edge_distance` (0, the default, is an unbounded "
            "plate) and read `monitor.edge_echo`, the first echo's return time 2a/c_L (c_L the plate's P-wave "
            "speed, the fastest: a conservative estimate) over the contact time; below 1 (`monitor.edge_clear` "
            "false) an echo arrives during the contact.",
            "Plastic deformation and plate waves take place concurrently, during the same contact; Eq. (20) "
            "combines their losses on that assumption. The monitor: `monitor.wave_delay`, how much the waves "
            "lengthen the contact; above 1.8136 (`monitor.concurrent` false) the delay exceeds what the paper "
            "validated.",
            "An impact outside the validated domain (\u03bb > 1.5, V* > 1000, e < 0, an edge echo during the "
            "contact) is logged once per instance and condition, with a warning in category logStatusWarning "
            "naming the quantity, its value and the limit; the call returns OK.",
            "`valid` is true inside both models' validated ranges: \u03bb \u2264 1.5 (Zener's studied range, "
            "`zener.in_range`) and V* \u2264 1000 (the range of the JGM fits, `jgm.in_range`). Outside them the "
            "FMU still computes and reports; nothing is clipped.",
            "The declared ranges of the inputs and parameters are the package's domain, inside which every output "
            "is finite; they are wider than the validated ranges.",
            "The paper fit (`zener_method` = 2) is 20 % off in e_ze at \u03bb = 1.5 and diverges above "
            "\u03bb \u2248 2; exact (1), the default, follows the ODE to 1e-8.",
        ),
    )),
)
