"""The order of the gallery's recipes (sphinx-gallery's ``within_subsection_order``): from the
package alone to the FMUs, each building on what the ones before showed."""
from __future__ import annotations

RECIPES = (
    "custom_material.py",
    "plot_e_against_thickness.py",
    "plot_fit_plate_yield_strength.py",
    "plot_monte_carlo_e.py",
    "fmi2_fmu_in_fmpy.py",
    "fmi3_fmu_in_fmpy.py",
    "plot_model_exchange_bounce.py",
    "plot_mujoco_velocity_dependent.py",
)


class RecipeOrder:
    """Sort key: a recipe's place in :data:`RECIPES`; a recipe not listed comes after them, by name."""

    def __init__(self, src_dir):
        self.src_dir = src_dir

    def __call__(self, filename: str):
        return (RECIPES.index(filename), "") if filename in RECIPES else (len(RECIPES), filename)

    def __repr__(self) -> str:  # sphinx-gallery shows it in its configuration summary
        return f"RecipeOrder{RECIPES}"
