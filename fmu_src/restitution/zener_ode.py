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

Zener's own first-order form is used (see ERRATA.md, "Numerical notes for
Eq. (10)/(21)"):

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
  ~4.5 lambda^(5/3) steps: 0.4 s at lambda = 100, ~15 min at 1e4) and LSODA
  (automatic Adams/BDF switching, analytic Jacobian) is used instead.  LSODA
  is ~10-20x cheaper than Radau here (<= 0.2 s up to lambda = 1e4 even at
  rtol = 1e-13, ~0.35 s at 1e8) but less faithful to its tolerance: its
  achieved relative error is about 10-50 rtol (measured ~5e-11 at
  rtol = 1e-12, ~1e-11 at rtol = 1e-13).  Should LSODA fail (seen at
  rtol = 1e-3 for lambda >= 1e6), the solve is repeated with Radau.  Pass
  method='Radau' or 'DOP853' to override.  Checked from lambda = 0 to 1e8
  for rtol in [1e-13, 1e-3].
* For large lambda the final values are tiny (e_ze ~ 0.679 lambda^-5), so
  the default absolute tolerance scales with that size.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

__all__ = ["solve_zener_ode", "solve_zener_ode_array", "STIFF_LAMBDA"]

#: lambda [1] above which the stiff-capable LSODA is used instead of DOP853.
STIFF_LAMBDA = 10.0


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


def _rhs_factory(lam):
    sqrt = math.sqrt

    def rhs(t, y):
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


def solve_zener_ode(lam, rtol=1e-10, atol=None, method=None, max_step=np.inf):
    """Zener's COR and contact time from a direct ODE solve.

    Integrates I. Green, Nonlinear Dyn (2022), Eq. (10) with Eq. (11) (Zener,
    Phys. Rev. 59 (1941)) in Zener's first-order form with
    scipy.integrate.solve_ivp up to the first return of sigma to zero.

    Parameters
    ----------
    lam : float
        Zener's "inelasticity" parameter lambda [1], Eq. (12); finite, >= 0.
    rtol : float
        Relative tolerance [1] handed to solve_ivp (default 1e-10).  The
        achieved relative error of e_ze and tau0 is about rtol with DOP853
        (lambda <= 10) and about 10-50 rtol with LSODA (lambda > 10); it
        levels off near 1e-12.
    atol : float or None
        Absolute tolerance [1] for (sigma, p).  Default
        rtol * 1e-6 * min(1, lambda^-5), which follows the size of the final
        velocity e_ze ~ 0.68 lambda^-5 at large lambda.
    method : str or None
        solve_ivp method.  Default: 'DOP853' for lambda <= STIFF_LAMBDA,
        'LSODA' (with analytic Jacobian) above, where the problem is stiff.
    max_step : float
        Largest step in tau [1] (default unlimited).

    Returns
    -------
    e_ze : float
        Zener's coefficient of restitution [1], -sigma'(tau0), the quantity
        fitted by Eq. (13).  e_ze = 1 for lambda = 0.
    tau0 : float
        Nondimensional contact time [1] (time of the first return of sigma to
        0), the quantity fitted by Eq. (13a); 2 (5/4)^(2/5) (2/5) B(2/5, 1/2)
        = 3.2180655 for lambda = 0.

    Raises
    ------
    ValueError
        If lambda is negative or not finite.
    RuntimeError
        If the integration fails or no rebound is found.
    """
    lam = _check_lambda(lam)
    rtol = float(rtol)
    auto = method is None
    if auto:
        method = "DOP853" if lam <= STIFF_LAMBDA else "LSODA"
    if atol is None:
        atol = max(rtol * 1e-6 * min(1.0, lam**-5.0 if lam > 0.0 else 1.0), 1e-300)
    ts, sig0, p0 = _start_state(lam)
    rhs, jac, event = _rhs_factory(lam)
    # tau0 < 4 for lam <= 1 and ~ lam (5 ln lam - 0.36) for large lam.
    t_end = 20.0 + 2.0 * lam * (5.0 * math.log1p(lam) + 1.0)
    sol = _integrate(rhs, jac, event, ts, t_end, sig0, p0, method, rtol, atol, max_step)
    ok = sol.status >= 0 and len(sol.t_events[0]) > 0
    if not ok and auto and method != "Radau":
        # LSODA gives up at loose tolerances for lambda >~ 1e6: retry with Radau.
        method = "Radau"
        sol = _integrate(rhs, jac, event, ts, t_end, sig0, p0, method, rtol, atol, max_step)
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
    return e_ze, tau0


#: tau0 at lambda = 0 (Hertz): 2 (5/4)^(2/5) (2/5) B(2/5, 1/2) [1].
_TAU0_LAMBDA0 = 2.0 * 1.25 ** 0.4 * 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


def _integrate(rhs, jac, event, ts, t_end, sig0, p0, method, rtol, atol, max_step):
    from scipy.integrate import solve_ivp  # lazy: keeps `import restitution` light (~0.4 s)

    kw = {"jac": jac} if method in ("Radau", "BDF", "LSODA") else {}
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
