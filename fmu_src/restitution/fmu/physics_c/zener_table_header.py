"""Generate the C header of the ``exact`` Zener method's table from the package's own pieces.

The pieces are exactly those :mod:`restitution.zener_exact` evaluates (its ``_COEF_ARR``, built from
``data/zener_table.npz``): one row per distinct Hermite piece (k, a0..a3 for e_ze, c0..c3 for
1 - e_ze, b0..b3 for tau0) and, per fine cell of width h, the index of its piece. Every double is
written as a C99 hexadecimal literal, so the C table holds the same bits as the Python one. The
large-lambda constants (E_INF, the Chebyshev series of g) and the per-method tau0 at lambda = 0
come from the package too.

    python -m restitution.fmu.physics_c.zener_table_header > rst_zener_table.h
"""
from __future__ import annotations

import sys

import numpy as np

from ... import zener, zener_exact


def _hex(x: float) -> str:
    x = float(x)
    if x != x or x in (float("inf"), float("-inf")):
        raise ValueError(f"non-finite table value {x!r}")
    return x.hex()


def zener_table_header() -> str:
    """C99 source of ``rst_zener_table.h`` (static const data and #defines only)."""
    cells = np.asarray(zener_exact._COEF_ARR)
    k = cells[:, 0]
    starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
    pieces = cells[starts]
    cell_to_piece = np.searchsorted(k[starts], k)
    if not np.array_equal(pieces[cell_to_piece], cells):
        raise RuntimeError("zener_exact pieces are not shared per distinct k")
    if len(pieces) >= 65536:
        raise RuntimeError("too many pieces for an unsigned short index")
    lines = [
        "/* The \"exact\" Zener method's table: generated at build time by",
        " * restitution.fmu.physics_c.zener_table_header from restitution/data/zener_table.npz",
        " * (the pieces restitution.zener_exact evaluates, bit for bit). Do not edit: rebuild. */",
        "#ifndef RST_ZENER_TABLE_H",
        "#define RST_ZENER_TABLE_H",
        f"#define RST_ZT_H {_hex(zener_exact._H)}",
        f"#define RST_ZT_INV_H {_hex(zener_exact._INV_H)}",
        f"#define RST_ZT_LAMBDA_MAX {_hex(zener_exact.LAMBDA_TABLE_MAX)}",
        f"#define RST_ZT_E_INF {_hex(zener_exact.E_INF)}",
        f"#define RST_ZT_U_MAX {_hex(zener_exact._U_MAX)}",
        f"#define RST_TAU0_HERTZ {_hex(zener.TAU0_HERTZ)}",
        f"#define RST_TAU0_PAPER_FIT_0 {_hex(zener.zener_paper_fit(0.0)[1])}",
        f"#define RST_TAU0_LINEAR_0 {_hex(zener.zener_linear(0.0)[1])}",
        f"#define RST_PAPER_FIT_LAMBDA_CAP {_hex(zener._PAPER_FIT_LAMBDA_CAP)}",
        f"#define RST_WAVE_DELAY_LIMIT {_hex(zener.WAVE_DELAY_LIMIT)}",
        f"#define RST_ZT_N_CHEB {len(zener_exact._G_CHEB)}",
        f"#define RST_ZT_N_PIECES {len(pieces)}",
        f"#define RST_ZT_N_CELLS {len(cells)}",
        "static const double RST_ZT_G_CHEB[RST_ZT_N_CHEB] = {",
        "    " + ", ".join(_hex(c) for c in zener_exact._G_CHEB),
        "};",
        "/* k, a0..a3 (e_ze), c0..c3 (1 - e_ze), b0..b3 (tau0) */",
        "static const double RST_ZT_PIECES[RST_ZT_N_PIECES][13] = {",
    ]
    lines += ["    {" + ", ".join(_hex(x) for x in row) + "}," for row in pieces]
    lines += ["};", "static const unsigned short RST_ZT_CELL_PIECE[RST_ZT_N_CELLS] = {"]
    idx = [str(int(j)) for j in cell_to_piece]
    lines += ["    " + ",".join(idx[i:i + 32]) + "," for i in range(0, len(idx), 32)]
    lines += ["};", "#endif", ""]
    return "\n".join(lines)


if __name__ == "__main__":
    sys.stdout.write(zener_table_header())
