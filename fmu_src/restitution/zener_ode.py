"""Direct numerical solution of Zener's impact ODE (the "ode" method).

This is the slow reference end of the package's accuracy scale for Zener's
coefficient of restitution.  It integrates

    I. Green, Nonlinear Dyn (2022), Eq. (10):
        sigma'' + (1 + lambda d/dtau) sigma^(3/2) = 0,
    with the initial conditions of Eq. (11):
        sigma(0) = 0,  sigma'(0) = 1,

where sigma [1] is Zener's nondimensional interference, tau [1] his
nondimensional time (Eq. (9)) and lambda [1] his "inelasticity" parameter
(Eq. (12)).  The expanded form is Eq. (21).

Zener's own first-order form is used (see docs/paper_departures.md, "Numerics of
Eq. (10)"):

    p      = sigma' + lambda sigma^(3/2)
    sigma' = p - lambda max(sigma, 0)^(3/2)
    p'     = -max(sigma, 0)^(3/2)

which is C^1 at sigma = 0, unlike Eq. (21) whose Jacobian is singular there.
The rebound (separation) is the first return of sigma to 0 while falling, at
tau = tau0 > 0; there sigma' = p, so Zener's coefficient of restitution is
e_ze = -sigma'(tau0) = -p(tau0) (the paper's sign convention after Eq. (13)).

Implementation notes
--------------------
* The first (at most 1e-5) of tau is covered by the analytic start series
  sigma = tau - (2/5) lam tau^(5/2) - (4/35) tau^(7/2) + (3/20) lam^2 tau^4,
  p     = 1 - (2/5) tau^(5/2) + (3/20) lam tau^4,
  (truncation error below 1e-17 relative), so the integration starts at
  sigma > 0 and the terminal event (sigma = 0, direction falling) cannot fire
  at tau = 0.
* lambda <= STIFF_LAMBDA (=10) uses the explicit 8th-order DOP853; its
  achieved relative error in e_ze and tau0 is about rtol (measured: <= 1.3
  rtol for rtol in [1e-12, 1e-6]).  For larger lambda the trajectory creeps
  down a strongly attracting slow manifold (lambda sigma^(3/2) ~ p) for a
  time ~ 5 lambda ln(lambda); the problem is stiff (an explicit method needs
  ~4.5 lambda^(5/3) steps) and LSODA (automatic Adams/BDF switching, analytic
  Jacobian) is used instead.  Its achieved relative error is about 10-50 rtol
  (measured ~5e-11 at rtol = 1e-12, ~1.5e-11 at rtol = 1e-13).

Bounded cost (a departure from "integrate at every call")
----------------------------------------------------------
Every call does a bounded amount of work over the whole domain the FMU
declares (lambda from 0 to ~6e18, tolerance 1e-14 ... 1e-2):

* **Tolerance floor.**  The tolerance actually used is
  max(rtol, RTOL_FLOOR_NONSTIFF = 100 eps ~ 2.2e-14) for DOP853 (scipy's own
  floor, applied here explicitly and silently) and max(rtol, RTOL_FLOOR_STIFF
  = 1e-13) for LSODA.  Below 1e-13 LSODA stops with "excess accuracy
  requested" (measured from lambda ~ 100 at rtol 2.2e-14), and the Radau
  fallback it used to take cost 160 000-560 000 right-hand-side evaluations
  (10-40 s, 56 s reported at lambda ~ 1.3e18) for no gain: LSODA's accuracy
  levels off near 1e-11 whatever the tolerance.  A tighter rtol therefore
  gives the same result as the floor; nothing is lost that the integrator
  could have delivered.
* **lambda > LAMBDA_ODE_MAX (=100): the verified large-lambda form**
  e_ze = E_INF lambda^-5, tau0 = lambda (5 ln lambda + g(lambda^(-5/3))) of
  :mod:`restitution.zener_exact` (no ODE solve).  Why: there integration
  cannot add accuracy.  The form's neglected terms are ~exp(-3 lambda^(5/3))
  (below double precision from lambda ~ 6) and its constants were fitted to
  rtol = 1e-13 solves: it agrees with independent direct solves to ~1e-12 in
  e_ze and tau0 (tests/physics/test_ode_cost.py checks 1e-10 at lambda = 1e3, 1e5,
  1e10, 1e18 against a loose-enough reference), whereas LSODA at its tightest
  honoured tolerance reaches only ~5e-12-1e-11 there, at a cost growing
  like ln(lambda) (55 000 evaluations, ~0.9 s, at lambda = 1.3e18) and, at
  loose tolerances (lambda >~ 1e6), failing over to Radau (~0.2-0.8 s).  The
  switch departs from the paper's procedure (a solve of Eq. (10) for every
  lambda), not from its model: the form is the solution of Eq. (10) to
  better than the integrator's accuracy.  It is independent of rtol (more
  accurate than any rtol >= 1e-11 asks for).
* **A work guard.**  Each call counts right-hand-side evaluations; past
  MAX_RHS_EVALUATIONS (=60 000, about 3x the most measured on the domain)
  it stops with RuntimeError (the FMU then reports the evaluation as failed,
  logged, fmi2Discard on a step) instead of running on.  On the declared
  domain it never fires: the most measured is ~18 000 evaluations (LSODA in
  its Adams mode near lambda = 100, rtol ~ 3e-11; ~0.35 s), ~14 000 for
  DOP853 (lambda = 10, rtol <= 2.2e-14; ~0.2 s); see
  benchmarks/bench_ode_cost.py and docs/ode_cost.md.
* For large lambda the final values are tiny (e_ze ~ 0.679 lambda^-5), so
  the default absolute tolerance scales with that size.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

__all__ = ["solve_zener_ode", "solve_zener_ode_array", "STIFF_LAMBDA", "LAMBDA_ODE_MAX",
           "RTOL_FLOOR_NONSTIFF", "RTOL_FLOOR_STIFF", "MAX_RHS_EVALUATIONS"]

#: lambda [1] above which the stiff-capable LSODA is used instead of DOP853.
STIFF_LAMBDA = 10.0
#: lambda [1] above which the verified large-lambda form replaces the solve (see module doc).
LAMBDA_ODE_MAX = 100.0
#: Tightest relative tolerance [1] used with DOP853 (scipy's floor, 100 machine epsilons).
RTOL_FLOOR_NONSTIFF = float(100.0 * np.finfo(float).eps)
#: Tightest relative tolerance [1] used with LSODA (tighter: LSODA fails, no accuracy gained).
RTOL_FLOOR_STIFF = 1e-13
#: Right-hand-side evaluations [1] after which one call gives up (never reached on the domain).
MAX_RHS_EVALUATIONS = 60_000


class _WorkBoundExceeded(Exception):
    """Raised inside the right-hand side when a call has used up MAX_RHS_EVALUATIONS."""


def _check_lambda(lam):
    try:
        lam_f = float(lam)
    except (TypeError, ValueError):
        raise ValueError(
            f"lambda must be a real number in [0, inf), got lambda={lam!r}"
        ) from None
    if not (lam_f >= 0.0 and math.isfinite(lam_f)):
        raise ValueError(
            f"lambda must be finite and >= 0 (allowed range [0, inf)), "
            f"got lambda={lam_f!r}"
        )
    return lam_f


def _start_state(lam):
    """Analytic start series of Eq. (10)-(11) at a tiny tau_s > 0.

    Returns (tau_s, sigma(tau_s), p(tau_s)), all [1].  The neglected terms are
    O(lam tau^5, lam^3 tau^(11/2), tau^5) and tau_s is chosen so that they are
    below 1e-17 relative to sigma.
    """
    cand = [1e-5]
    if lam > 0.0:
        cand.append((1e-17 / lam) ** 0.25)
        cand.append((1e-17 / lam**3) ** (1.0 / 4.5))
    ts = min(cand)
    r = math.sqrt(ts)
    t25 = ts * ts * r
    t35 = t25 * ts
    t4 = ts**4
    sig = ts - 0.4 * lam * t25 - (4.0 / 35.0) * t35 + 0.15 * lam * lam * t4
    p = 1.0 - 0.4 * t25 + 0.15 * lam * t4
    return ts, sig, p


def _rhs_factory(lam, budget):
    """(rhs, jac, event) of Zener's first-order form of Eq. (10) [1]; rhs counts its calls
    in budget[0] and raises _WorkBoundExceeded past budget[1]."""
    sqrt = math.sqrt

    def rhs(t, y):
        budget[0] += 1
        if budget[0] > budget[1]:
            raise _WorkBoundExceeded
        s = float(y[0])
        if s > 0.0:
            q = s * sqrt(s)
        else:  # clamp: a trial step past the rebound must not take sqrt(<0)
            q = 0.0
        return [float(y[1]) - lam * q, -q]

    def jac(t, y):
        s = float(y[0])
        r = 1.5 * sqrt(s) if s > 0.0 else 0.0
        return [[-lam * r, 1.0], [-r, 0.0]]

    def event(t, y):
        return y[0]

    event.terminal = True
    event.direction = -1.0
    return rhs, jac, event


def solve_zener_ode(lam, rtol=1e-10, atol=None, method=None, max_step=np.inf, full_output=False):
    """Zener's COR and contact time from a direct ODE solve.

    Integrates I. Green, Nonlinear Dyn (2022), Eq. (10) with Eq. (11) (Zener,
    Phys. Rev. 59 (1941)) in Zener's first-order form with
    scipy.integrate.solve_ivp up to the first return of sigma to zero.  For
    lambda > LAMBDA_ODE_MAX (=100) and ``method=None`` it returns the verified
    large-lambda form instead, and every call's work is bounded (see the
    module doc, "Bounded cost").

    Parameters
    ----------
    lam : float
        Zener's "inelasticity" parameter lambda [1], Eq. (12); finite, >= 0.
    rtol : float
        Relative tolerance [1] asked for (default 1e-10); > 0.  Raised to
        RTOL_FLOOR_NONSTIFF (2.2e-14, DOP853) or RTOL_FLOOR_STIFF (1e-13,
        LSODA) where tighter.  The achieved relative error of e_ze and tau0
        is about rtol with DOP853 (lambda <= 10) and about 10-50 rtol with
        LSODA (10 < lambda <= 100); it levels off near 1e-12 and 1e-11.
        Above lambda = 100 (large-lambda form) it is ~1e-12 for every rtol.
    atol : float or None
        Absolute tolerance [1] for (sigma, p).  Default
        rtol * 1e-6 * min(1, lambda^-5), which follows the size of the final
        velocity e_ze ~ 0.68 lambda^-5 at large lambda.
    method : str or None
        solve_ivp method.  Default: 'DOP853' for lambda <= STIFF_LAMBDA,
        'LSODA' (with analytic Jacobian) up to LAMBDA_ODE_MAX, the
        large-lambda form above.  A method given explicitly is always
        integrated (any lambda; the tolerance floors and the work guard still
        apply): for studies, not for the FMU.
    max_step : float
        Largest step in tau [1] (default unlimited).
    full_output : bool
        Also return a dict describing the work done (default False).

    Returns
    -------
    e_ze : float
        Zener's coefficient of restitution [1], -sigma'(tau0), the quantity
        fitted by Eq. (13).  e_ze = 1 for lambda = 0.
    tau0 : float
        Nondimensional contact time [1] (time of the first return of sigma to
        0), the quantity fitted by Eq. (13a); 2 (5/4)^(2/5) (2/5) B(2/5, 1/2)
        = 3.2180655 for lambda = 0.
    info : dict, only with ``full_output=True``
        ``method`` (the solve_ivp method(s) used, '+'-joined, or
        'large-lambda form'), ``rtol`` [1] (the tolerance used after the
        floor), ``nfev`` [1] (right-hand-side evaluations, counted here),
        ``njev`` [1] (Jacobian evaluations), ``nsteps`` [1] (accepted steps).

    Raises
    ------
    ValueError
        If lambda is negative or not finite, or rtol is not a positive number.
    RuntimeError
        If the integration fails, no rebound is found, or the call reaches
        MAX_RHS_EVALUATIONS right-hand-side evaluations (the work guard).
    """
    lam = _check_lambda(lam)
    rtol = float(rtol)
    if not rtol > 0.0:  # also nan
        raise ValueError(f"rtol must be > 0, got rtol={rtol!r}")
    auto = method is None
    if auto and lam > LAMBDA_ODE_MAX:
        e_ze, tau0 = _large_lambda_form(lam)
        info = {"method": "large-lambda form", "rtol": rtol, "nfev": 0, "njev": 0, "nsteps": 0}
        return (e_ze, tau0, info) if full_output else (e_ze, tau0)
    if auto:
        method = "DOP853" if lam <= STIFF_LAMBDA else "LSODA"
    rtol = max(rtol, RTOL_FLOOR_STIFF if method in ("LSODA", "Radau", "BDF") else RTOL_FLOOR_NONSTIFF)
    if atol is None:
        atol = max(rtol * 1e-6 * min(1.0, lam**-5.0 if lam > 0.0 else 1.0), 1e-300)
    ts, sig0, p0 = _start_state(lam)
    budget = [0, MAX_RHS_EVALUATIONS]
    rhs, jac, event = _rhs_factory(lam, budget)
    # tau0 < 4 for lam <= 1 and ~ lam (5 ln lam - 0.36) for large lam.
    t_end = 20.0 + 2.0 * lam * (5.0 * math.log1p(lam) + 1.0)
    used = [method]
    njev = nsteps = 0
    sol = _integrate(rhs, jac, event, ts, t_end, sig0, p0, method, rtol, atol, max_step, budget, lam)
    njev, nsteps = njev + int(sol.njev), nsteps + len(sol.t) - 1
    ok = sol.status >= 0 and len(sol.t_events[0]) > 0
    if not ok and auto and method != "Radau":
        # LSODA has been seen to give up at loose tolerances for lambda >~ 1e6 (now handled by the
        # large-lambda form); kept as a safety net, inside the same work budget.
        method = "Radau"
        used.append(method)
        sol = _integrate(rhs, jac, event, ts, t_end, sig0, p0, method, rtol, atol, max_step, budget, lam)
        njev, nsteps = njev + int(sol.njev), nsteps + len(sol.t) - 1
        ok = sol.status >= 0 and len(sol.t_events[0]) > 0
    if not ok:
        if sol.status < 0:
            raise RuntimeError(
                f"Zener ODE integration ({method}) failed for lambda={lam!r}: {sol.message}"
            )
        raise RuntimeError(
            f"no rebound (sigma = 0) found for lambda={lam!r} before tau={t_end}"
        )
    # Project onto bounds that hold exactly for lambda >= 0 (damping never adds energy and
    # never shortens the contact): e_ze <= 1 and tau0 >= tau0(0). Integration error alone
    # gave e_ze = 1 + 6e-11 at lambda = 0, rtol = 1e-10 (and 1.002 at rtol = 1e-2); the
    # projection can only move the result toward the true value.
    tau0 = max(float(sol.t_events[0][0]), _TAU0_LAMBDA0)
    e_ze = min(-float(sol.y_events[0][0][1]), 1.0)
    if full_output:
        return e_ze, tau0, {"method": "+".join(used), "rtol": rtol, "nfev": budget[0], "njev": njev,
                            "nsteps": nsteps}
    return e_ze, tau0


#: tau0 at lambda = 0 (Hertz): 2 (5/4)^(2/5) (2/5) B(2/5, 1/2) [1].
_TAU0_LAMBDA0 = 2.0 * 1.25 ** 0.4 * 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


def _large_lambda_form(lam):
    """(e_ze, tau0) [1] for lambda > LAMBDA_ODE_MAX: the verified large-lambda solution of Eq. (10)-(11),
    e_ze = E_INF lambda^-5 (the quantity of Eq. (13)), tau0 = lambda (5 ln lambda + g(lambda^(-5/3)))
    (the quantity of Eq. (13a)), from :mod:`restitution.zener_exact` (why and how accurate: module doc)."""
    from .zener_exact import zener_exact  # lazy: zener_exact loads its table at import

    e_ze, tau0 = zener_exact(lam)
    return float(e_ze), float(tau0)


def _integrate(rhs, jac, event, ts, t_end, sig0, p0, method, rtol, atol, max_step, budget, lam):
    from scipy.integrate import solve_ivp  # lazy: keeps `import restitution` light (~0.4 s)

    kw = {"jac": jac} if method in ("Radau", "BDF", "LSODA") else {}
    try:
        with warnings.catch_warnings():
            # LSODA reports its failures as warnings too; the status is checked.
            warnings.simplefilter("ignore", UserWarning)
            return solve_ivp(
                rhs,
                (ts, t_end),
                [sig0, p0],
                method=method,
                rtol=rtol,
                atol=atol,
                events=event,
                max_step=max_step,
                **kw,
            )
    except _WorkBoundExceeded:
        raise RuntimeError(
            f"Zener ODE integration ({method}) for lambda={lam!r} at rtol={rtol!r} stopped after "
            f"{budget[1]} right-hand-side evaluations, the work bound of one call"
        ) from None


def solve_zener_ode_array(lam_array, rtol=1e-10, atol=None, method=None):
    """Vectorised convenience wrapper of solve_zener_ode (a plain loop).

    Parameters
    ----------
    lam_array : array_like
        lambda values [1] (Eq. (12)), any shape, each finite and >= 0.
    rtol, atol, method :
        As for solve_zener_ode.

    Returns
    -------
    e_ze, tau0 : ndarray
        Arrays of the input shape: Zener's COR [1] (fitted by Eq. (13)) and
        the contact time [1] (fitted by Eq. (13a)).
    """
    lam_arr = np.asarray(lam_array, dtype=float)
    e = np.empty(lam_arr.shape)
    t = np.empty(lam_arr.shape)
    for idx, lam in np.ndenumerate(lam_arr):
        e[idx], t[idx] = solve_zener_ode(lam, rtol=rtol, atol=atol, method=method)
    return e, t
