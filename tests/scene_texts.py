"""The scene text the scene tests share: one steel sphere dropped on one aluminium plate (the Table 3
pair of the paper), written as a scene file's ``[[plates]]`` and ``[[balls]]`` tables. Values are TOML
as they stand in a file (quoted where they carry a unit)."""


def steel_on_aluminium(heights: str = '"0.1 m"', thickness: str = '"3.18 mm"', diameter: str = '"6.35 mm"') -> str:
    """The ``[[plates]]`` and ``[[balls]]`` tables of an S2 tool steel sphere of ``diameter`` dropped from
    ``heights`` on an Al 6061 plate of ``thickness``."""
    return f"""
[[plates]]
name = "plate"
material = "al_6061"
thickness = {thickness}

[[balls]]
name = "ball"
material = "s2_tool_steel"
diameter = {diameter}
drop_heights = {heights}
"""
