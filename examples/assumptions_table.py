"""The assumption monitors for the paper's own experiments: the table of docs/assumptions.md.

    python examples/assumptions_table.py

Green (Nonlinear Dyn 2022, section 5) compares Eq. (20) with the drop tests of Patil and Higgs:
Al 6061 plates, 152.4 mm square, struck at the centre, several thicknesses, two ball diameters,
2.3 m/s. This script evaluates :func:`restitution.impact` for that geometry, once for the S2
tool-steel ball and once for the borosilicate-glass ball, and prints one markdown table per ball:
how far each impact sits from the model's assumptions (``wave_delay``, ``edge_echo``) and the
apparent COR it predicts.

The output goes verbatim between the marker comments of docs/assumptions.md;
tests/docs/test_assumptions_page.py fails when the two differ. It carries no date or machine line
(unlike docs/accuracy.md): the numbers are deterministic physics, so a rerun on any machine must
reproduce the page byte for byte.
"""
from __future__ import annotations

import restitution as r

#: The experiments' common values (Green 2022, section 5, after Patil and Higgs).
SPEED = 2.3  # [m/s] impact speed of every drop
PLATE_SIDE = 152.4e-3  # [m] the plates are squares of this side ...
EDGE_DISTANCE = PLATE_SIDE / 2  # [m] ... struck at the centre: 76.2 mm to the nearest edge
DIAMETERS = (4.76e-3, 6.35e-3)  # [m] ball diameters
THICKNESSES = (1.6e-3, 3.18e-3, 4.76e-3, 6.35e-3, 9.53e-3, 12.7e-3)  # [m] plate thicknesses
PLATE = "al_6061"
#: The balls shown, each a preset key of restitution.MATERIALS. Both are harder than the plate, so in
#: both the plate yields (Eq. 2); the glass one is brittle (never yields) and lighter.
BALLS = ("s2_tool_steel", "borosilicate_glass")

COLUMNS = ("d [mm]", "t [mm]", "t/d [1]", "λ [1]", "wave_delay [1]", "concurrent", "edge_echo [1]",
           "edge_clear", "e [1]")


def rows(ball: str) -> list[dict]:
    """One dict per (diameter, thickness) of the experiments for ``ball`` (a preset key): the geometry
    [m] and the :class:`restitution.ImpactResult` of the impact, in the table's order."""
    out = []
    for d in DIAMETERS:
        sphere = r.Sphere(r.MATERIALS[ball], d)
        for t in THICKNESSES:
            plate = r.Plate(r.MATERIALS[PLATE], t)
            result = r.impact(SPEED, **sphere.params(), **plate.params(), plate_edge_distance=EDGE_DISTANCE)
            out.append({"ball": ball, "d": d, "t": t, "result": result})
    return out


def _flag(value: bool) -> str:
    # a failed check in bold, so that the eye finds it in a column of "yes"
    return "yes" if value else "**no**"


def _row_text(row: dict) -> str:
    res = row["result"]
    # 3 decimals for edge_echo: several plates sit within 1 % of its threshold 1, and the table must
    # show on which side; 4 for e: one case is negative by only 0.005
    cells = (f"{row['d'] * 1e3:.2f}", f"{row['t'] * 1e3:.2f}", f"{row['t'] / row['d']:.3f}", f"{res.lam:#.3g}",
             f"{res.wave_delay:.3f}", _flag(res.concurrent), f"{res.edge_echo:.3f}", _flag(res.edge_clear),
             f"{res.e:.4f}")
    return "| " + " | ".join(cells) + " |"


def markdown() -> str:
    """The tables, one per ball, as the page shows them (ending in a newline)."""
    blocks = []
    for ball in BALLS:
        title = (f"**{r.MATERIALS[ball].name} ball (`{ball}`) on {r.MATERIALS[PLATE].name} (`{PLATE}`)**, "
                 f"v = {SPEED} m/s, a = {EDGE_DISTANCE * 1e3:.1f} mm")
        lines = [title, "", "| " + " | ".join(COLUMNS) + " |",
                 "|" + "|".join("---:" if "[" in c else "---" for c in COLUMNS) + "|"]
        lines += [_row_text(row) for row in rows(ball)]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks) + "\n"


if __name__ == "__main__":
    print(markdown(), end="")
