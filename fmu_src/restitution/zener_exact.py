"""Zener's COR and contact time, to ODE accuracy at closed-form cost (the "exact" method).

Solves, in effect, I. Green, Nonlinear Dyn (2022), Eq. (10) with Eq. (11) (Zener, Phys. Rev.
59 (1941)): sigma'' + (1 + lambda d/dtau) sigma^(3/2) = 0, sigma(0) = 0, sigma'(0) = 1, and
returns e_ze = -sigma'(tau0) [1] (the quantity fitted by Eq. (13)) and the contact time tau0
[1] (fitted by Eq. (13a)), tau0 being the first return of sigma to 0.

How
---
* 0 <= lambda <= 100: C^1 piecewise-cubic Hermite interpolation of e_ze and tau0 from
  values and slopes tabulated offline (data/zener_table.npz, 90 kB, made by
  build_scripts/make_zener_table.py from rtol = 1e-13 solves) at 2148 nodes on the grid
  lambda = k/128, spaced 1/128 where e_ze is most curved (lambda < ~5) and wider as
  e_ze ~ lambda^-5 flattens (widths 2^n/128, 1/4 at most).  A list over all 12801 cells of
  width 1/128 points at the shared pieces, so locating a piece is one multiply and int().
  Measured relative error against fresh independent solves between the nodes:
  <= 4.1e-10 for e_ze and <= 3e-11 for tau0 (bound 1e-8).  The table reproduces
  e_ze(0) = 1 and tau0(0) = 2 (5/4)^(2/5) (2/5) B(2/5, 1/2) = 3.2180655 exactly.
* lambda > 100: a verified large-lambda form (no ODE solve).  The substitution
  sigma = lambda^-4 S, p = lambda^-5 P, tau = lambda T maps the problem onto the lambda = 1
  system with initial velocity lambda^5: a fast initial layer, a long creep down the
  attracting slow manifold lambda sigma^(3/2) ~ p, and a universal final ejection.  Hence

      e_ze = E_INF lambda^-5,                          E_INF = 0.679293063936
      tau0 = lambda (5 ln lambda + g(lambda^(-5/3))),  g(u) = G0 + 3 u + 0.9575 u^2 + ...,
                                                        G0 = -0.359367056648

  with g a Chebyshev series fitted to direct solves (lambda = 6 ... 190).  The neglected
  terms decay like exp(-c lambda^(5/3)), c ~ 3 (in e_ze: 3e-6 at lambda = 3, < 1e-13
  from lambda = 4; in tau0: 2e-8 at lambda = 5, < 1e-14 from lambda = 6).
  Checked against direct ODE solves at lambda = 150, 1000, 1e4: relative error < 1e-11
  in e_ze and < 2e-13 in tau0.  The form is continuous (value and slope) with the table
  at lambda = 100, whose nodes above lambda = 6 come from the same form.  e_ze underflows
  to 0 only for lambda > ~1e61.

Cost (measured, Python 3.11, numpy 2.4, 2-core AMD EPYC VM): a Python float in [0, 100]
takes ~0.34 us, 1.8x the closed-form fit math.exp(-1.68374 lambda), 3.215 math.exp(0.318
lambda^1.5) of Eqs. (13)/(13a) (~0.18 us), also for random lambda over [0, 100]; other
scalars (int, numpy scalars) ~0.6 us, lambda > 100 ~1.7 us.  Arrays of 1e5 elements:
~25-45 ns per element, 1.05-1.2x the numpy evaluation of the same fit.  Import: ~20 ms,
~2 MB.
"""

from __future__ import annotations

import io
import math
from importlib.resources import files

import numpy as np

__all__ = ["zener_exact", "zener_exact_solution", "LAMBDA_TABLE_MAX", "E_INF", "TAU0_LAMBDA0"]

_DATA_NAME = "zener_table.npz"


def _load_table():
    """The arrays of data/zener_table.npz, read through importlib.resources (also from a zip)."""
    data = files(__package__).joinpath("data", _DATA_NAME).read_bytes()
    with np.load(io.BytesIO(data)) as d:
        return {k: d[k] for k in d.files}


def _hermite(k, f, df, h):
    """Pieces a0 + t (a1 + t (a2 + t a3)), t = lambda/h - k_j in [0, w_j), w_j = k_{j+1} - k_j.

    The widths w_j are powers of 2, so the divisions below are exact.
    """
    w = np.diff(k)
    hw = h * w
    f0, f1, d0, d1 = f[:-1], f[1:], hw * df[:-1], hw * df[1:]
    return (f0, d0 / w, (3.0 * (f1 - f0) - 2.0 * d0 - d1) / w**2,
            (2.0 * (f0 - f1) + d0 + d1) / w**3)


def _build_pieces(T, h, lam_max):
    """(pieces per fine cell as tuples, the same as an array) from the table T, node spacing h, table end lam_max."""
    k = T["k"]
    if k[0] != 0 or np.any(np.diff(k) <= 0) or k[-1] * h <= lam_max:
        raise RuntimeError(f"{_DATA_NAME}: bad node layout")
    # one row per piece: (k_j, a0..a3 for e_ze, c0..c3 for 1 - e_ze, b0..b3 for tau0).
    # The deficit's pieces are c0 = 1 - a0 (exact: a0 >= 0.5 on every piece where it matters,
    # Sterbenz) and c_i = -a_i, so 1 - e_ze is interpolated directly: at small lambda it is
    # t (|a1| + ...) with full relative accuracy instead of the difference of two numbers near 1.
    a = _hermite(k, T["e"], T["de"], h)
    rows = np.stack((k[:-1],) + a + (1.0 - a[0], -a[1], -a[2], -a[3])
                    + _hermite(k, T["tau0"], T["dtau0"], h), axis=1)
    cell_to_piece = np.repeat(np.arange(len(rows)), np.diff(k))  # fine cell -> piece
    # scalar path: a list over fine cells whose entries share the piece tuples (small, and
    # an index costs one multiply and int()); array path: the same rows, expanded
    pieces = [tuple(r) for r in rows.tolist()]
    return [pieces[j] for j in cell_to_piece.tolist()], np.ascontiguousarray(rows[cell_to_piece])


def _tables(T):
    """Everything the evaluation reads, from the arrays T of data/zener_table.npz: (h, 1/h,
    LAMBDA_TABLE_MAX, E_INF, TAU0_LAMBDA0, u_max, the Chebyshev coefficients of g, the pieces per fine
    cell as tuples, as an array and as the array's columns). Called once, at import; the tests call it again on the data file
    and check what it builds against independent solves (a mutation tool switches its mutants on per
    call, after import, so this is how the build is reached)."""
    h = float(T["h"])
    lam_max = float(T["lam_table_max"])
    if lam_max != 100.0:  # the literal in zener_exact_solution's fast path must match the table
        raise RuntimeError(f"{_DATA_NAME}: expected a table up to lambda = 100, got {lam_max}")
    coef, coef_arr = _build_pieces(T, h, lam_max)
    # the array path gathers each coefficient from its own contiguous column: a large array never
    # builds the (n, 13) block of every case's piece, whose strided columns each Horner step streamed
    # through memory again (10^6 cases: 104 MB, read 12 times; the whole model took 1.7x as long)
    coef_cols = tuple(np.ascontiguousarray(coef_arr[:, j]) for j in range(coef_arr.shape[1]))
    return (h, 1.0 / h, lam_max, float(T["asym_E_inf"]), float(T["tau0"][0]), float(T["asym_u_max"]),
            [float(c) for c in T["asym_g_cheb"]], coef, coef_arr, coef_cols)


# LAMBDA_TABLE_MAX: upper end of the tabulated range of lambda [1]; above it the large-lambda form is used.
# E_INF: lim lambda^5 e_ze for lambda -> inf [1] (the large-lambda form e_ze = E_INF lambda^-5).
# TAU0_LAMBDA0: tau0 at lambda = 0, 2 (5/4)^(2/5) (2/5) B(2/5, 1/2) [1].
(_H, _INV_H, LAMBDA_TABLE_MAX, E_INF, TAU0_LAMBDA0, _U_MAX, _G_CHEB, _COEF, _COEF_ARR, _COEF_COLS) = _tables(
    _load_table())


def _bad_lambda(value, where=""):
    return ValueError(
        f"lambda must be finite and >= 0 (allowed range [0, inf)); got lambda={value!r}{where}"
    )


def _table_scalar(lam):
    """(e_ze, 1 - e_ze, tau0) of a float 0 <= lambda <= LAMBDA_TABLE_MAX: one piece, three cubics."""
    x = lam * _INV_H
    k, a0, a1, a2, a3, c0, c1, c2, c3, b0, b1, b2, b3 = _COEF[int(x)]
    t = x - k
    return (a0 + t * (a1 + t * (a2 + t * a3)), c0 + t * (c1 + t * (c2 + t * c3)),
            b0 + t * (b1 + t * (b2 + t * b3)))


def _asym(lam):
    """(e_ze, 1 - e_ze, tau0) [1] of the large-lambda form (lambda >= 6; used above LAMBDA_TABLE_MAX),
    for a float or an array: e_ze = E_INF lambda^-5, tau0 = lambda (5 ln lambda + g(lambda^(-5/3))), g by
    Clenshaw's recurrence on its Chebyshev series. u = lambda^(-5/3) and e_ze underflow to 0 for huge
    lambda (u from ~1e184, e_ze from ~1e61), harmlessly and silently on both paths (numpy's underflow
    flag is not raised to the caller); tau0 overflows to inf above lambda ~ 5e304."""
    with np.errstate(under="ignore", over="ignore"):
        u = lam ** (-5.0 / 3.0)
        z2 = 2.0 * (2.0 * u / _U_MAX - 1.0)
        c = _G_CHEB
        b1 = b2 = 0.0
        for k in range(len(c) - 1, 0, -1):
            b1, b2 = c[k] + z2 * b1 - b2, b1
        g = c[0] + 0.5 * z2 * b1 - b2
        e = E_INF * (1.0 / lam) ** 5
        # ln of a float (what the scalar paths pass) by the C library, of an array by numpy, as
        # restitution._num.log does: this module imports nothing of the package, so the ODE solver
        # (restitution.zener_ode) uses this form above its range without a chain of imports
        tau0 = lam * (5.0 * (math.log(lam) if lam.__class__ is float else np.log(lam)) + g)
    return e, 1.0 - e, tau0


def _scalar_general(lam):
    """Slow scalar path: ints, numpy scalars, lambda > LAMBDA_TABLE_MAX, and the errors."""
    if isinstance(lam, (complex, np.complexfloating)):  # float() would drop the imaginary part
        raise _bad_lambda(lam)
    try:
        x = float(lam)
    except (TypeError, ValueError):
        raise _bad_lambda(lam) from None
    if not (x >= 0.0 and x < math.inf):
        raise _bad_lambda(x)
    if x <= LAMBDA_TABLE_MAX:
        return _table_scalar(x)
    return _asym(x)


#: Cases per block of :func:`_table_array`: its temporaries (the local coordinate, the cell index, a
#: gathered column, a partial cubic: 4 x 256 kB) stay in the cache and are reused block after block,
#: instead of four fresh arrays of the whole size, which numpy takes from the system (and the system
#: must clear) once they pass ~32 MB.
_BLOCK = 32768


def _table_array(lam, e_only=False):
    """(e_ze, 1 - e_ze, tau0) of an array 0 <= lambda <= LAMBDA_TABLE_MAX: the pieces of
    :func:`_table_scalar`, with one cell index and one local coordinate t shared by both cubics.

    Each coefficient column is gathered once (9 gathers, not one per coefficient of the three cubics),
    and the deficit is not a third cubic: its pieces are (1 - a0, -a1, -a2, -a3), so with
    q = t (a1 + t (a2 + t a3)) the e_ze cubic is a0 + q and the deficit's is (1 - a0) - q, the same
    floating-point operations as Horner on the deficit's own pieces (negation is exact) and
    1 - a0 the same number as its column ``c0`` (both are that one subtraction). In place, in blocks
    of :data:`_BLOCK` cases written into the three results. ``e_only``: (e_ze,) alone, the same cubic
    without the other two (what ``impact(outputs=("e",))`` needs)."""
    results = tuple(np.empty(np.shape(lam)) for _ in range(1 if e_only else 3))  # their own memory, in lambda's shape
    flat = tuple(r.reshape(-1) for r in results)  # views, to write them block by block
    lam = np.ascontiguousarray(lam).reshape(-1)
    n = min(lam.size, _BLOCK)
    t, piece, gathered, q = np.empty(n), np.empty(n, dtype=np.intp), np.empty(n), np.empty(n)
    for start in range(0, lam.size, _BLOCK):
        stop = min(start + _BLOCK, lam.size)
        m = stop - start
        e, deficit, tau0 = (r[start:stop] for r in flat) if not e_only else (flat[0][start:stop], None, None)
        _table_block(lam[start:stop], e, deficit, tau0, t[:m], piece[:m], gathered[:m], q[:m])
    return results


def _table_block(lam, e, deficit, tau0, t, piece, gathered, q):
    """One block of :func:`_table_array`: the three cubics of the cases ``lam`` into ``e``, ``deficit`` and
    ``tau0`` (None: not computed), with the block's buffers ``t``, ``piece``, ``gathered`` and ``q``."""
    def gather(column, out=gathered):  # mode "clip": indices are in range, and no bounds pass is buffered
        return _COEF_COLS[column].take(piece, out=out, mode="clip")

    np.multiply(lam, _INV_H, out=t)
    np.copyto(piece, t, casting="unsafe")  # truncation: the fine cell
    t -= gather(0)  # now t, in [0, w) of the piece
    gather(4, q)
    q *= t
    q += gather(3)
    q *= t
    q += gather(2)
    q *= t
    gather(1, e)
    if deficit is not None:
        np.subtract(1.0, e, out=deficit)
        deficit -= q
    e += q
    if tau0 is None:
        return
    gather(12, tau0)
    for column in (11, 10, 9):
        tau0 *= t
        tau0 += gather(column)


def _array(lam):
    a = np.asarray(lam, dtype=float)
    if a.size == 0:
        return np.empty(a.shape), np.empty(a.shape), np.empty(a.shape)
    lo = a.min()
    hi = a.max()
    if not (lo >= 0.0 and hi < math.inf):  # also catches nan (min/max propagate it)
        bad = ~(np.isfinite(a) & (a >= 0.0))
        idx = tuple(int(j) for j in np.argwhere(bad)[0])  # () for a 0-d array
        raise _bad_lambda(float(a[idx]), f" (at index {idx})" if a.ndim else "")
    if a.ndim == 0:
        return tuple(np.array(x) for x in _scalar_general(float(a)))
    if hi <= LAMBDA_TABLE_MAX:
        return _table_array(a)
    big = a > LAMBDA_TABLE_MAX
    out = tuple(np.empty(a.shape) for _ in range(3))
    small = ~big
    for target, part in zip(out, _table_array(a[small])):
        target[small] = part
    for target, part in zip(out, _asym(a[big])):
        target[big] = part
    return out


def zener_exact(lam):
    """Zener's coefficient of restitution and contact time, to ODE accuracy, fast.

    The "exact" method: the solution of I. Green, Nonlinear Dyn (2022), Eq. (10) with
    Eq. (11) (Zener 1941), tabulated offline and interpolated for 0 <= lambda <= 100
    (relative error <= 5e-10), and a verified large-lambda form above (see module doc).

    Parameters
    ----------
    lam : float or array_like
        Zener's "inelasticity" parameter lambda [1], Eq. (12); finite and >= 0.
        A Python (or numpy) scalar gives Python floats; an array (any shape, including
        0-d) or a list gives ndarrays of that shape.  Array and scalar results agree to
        rounding: the same Horner evaluation up to lambda = 100; above, numpy's log/pow
        may differ from the C library's in the last bit.

    Returns
    -------
    e_ze : float or ndarray
        Zener's COR [1], -sigma'(tau0), the quantity of Eq. (13); 1 at lambda = 0,
        0.0664 at lambda = 1.5, ~0.679 lambda^-5 for large lambda.
    tau0 : float or ndarray
        Nondimensional contact time [1] (Eq. (9): t = T tau), the quantity of Eq. (13a);
        3.2180655 at lambda = 0, 5.836 at lambda = 1.5, ~lambda (5 ln lambda - 0.359)
        for large lambda.

    Raises
    ------
    ValueError
        If lambda (or any element) is negative, nan or infinite.
    """
    e, _, tau0 = zener_exact_solution(lam)
    return e, tau0


def zener_exact_restitution(lam):
    """e_ze [1] of the "exact" method alone: :func:`zener_exact_solution`'s first value, by the same
    operations, without the deficit and tau0 where an array lies in the table."""
    if (lam.__class__ is np.ndarray and lam.dtype == float and lam.ndim and lam.size
            and 0.0 <= lam.min() and lam.max() <= LAMBDA_TABLE_MAX):
        return _table_array(lam, e_only=True)[0]
    return zener_exact_solution(lam)[0]


def zener_exact_solution(lam):
    """(e_ze, 1 - e_ze, tau0) [1] of the "exact" method: :func:`zener_exact` and the deficit 1 - e_ze.

    The deficit is interpolated from its own pieces (1 - a0, -a1, -a2, -a3), not computed as
    1 - e_ze: near lambda = 0, where e_ze = 1 - 1.7302 lambda + ..., the subtraction would leave
    only the bits of lambda that survive rounding e_ze to a number near 1 (relative condition
    number ~ 1/(1 - e_ze), 1e16 at lambda ~ 1e-16). Interpolated directly it keeps full relative
    accuracy (condition number ~ 1 in lambda), and e_ze + (1 - e_ze) = 1 to rounding.
    """
    if lam.__class__ is float and 0.0 <= lam <= 100.0:  # the common case first (LAMBDA_TABLE_MAX = 100)
        return _table_scalar(lam)
    if isinstance(lam, (np.ndarray, list, tuple)) or np.ndim(lam) != 0:
        return _array(lam)
    return _scalar_general(lam)  # other scalars: int, numpy's, Fraction, Decimal; errors
