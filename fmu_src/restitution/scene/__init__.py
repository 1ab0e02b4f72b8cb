"""Scenes: balls dropped on plates, described in TOML files and simulated through the FMU,
computing only the effects the requested outputs need.

    restitution scene run examples/scenes/steel_ball_thick_steel_table.toml
    restitution scene report examples/scenes/*.toml --out docs/scenes.md

Host side only (needs the ``fmu`` extra, matplotlib for plots, tqdm for progress bars);
nothing in the physics modules or the FMU imports this subpackage. See docs/scenes.md.
"""
from .loader import (OUTPUTS, BallSpec, Drop, ModelSpec, PlateSpec, Scene, SceneError, SimulationSpec,
                     load_scene, parse_scene, resolve_material)
from .results import DropResult, SceneResult
from .runner import chosen_fmu, run_scene

__all__ = ["OUTPUTS", "BallSpec", "Drop", "ModelSpec", "PlateSpec", "Scene", "SceneError", "SimulationSpec",
           "load_scene", "parse_scene", "resolve_material", "DropResult", "SceneResult", "chosen_fmu", "run_scene"]
