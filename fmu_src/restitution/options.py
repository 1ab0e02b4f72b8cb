"""The command lines' option declarations (``restitution cor``, ``fit``, ``sweep``, ``scene``): argparse's
parser whose refusals are one short line, the material options and the rule for bare-number lengths in
the --help epilogs, with its numbers. Reading the values (and holding them to that rule) is
:mod:`restitution.inputs`'s, which reads what is declared here: declaring options loads no reader."""
from __future__ import annotations

import argparse

from .units import shorten_quoted

__all__ = ["ArgumentParser", "add_material_options", "add_impact_options", "BARE_NUMBER_RULE", "MATERIAL_PROPERTIES",
           "MAX_BARE_LENGTH", "PLAUSIBLE_T_OVER_D"]

#: A material's properties as options and file keys (``--plate-E``, ``E = "69 GPa"``): key -> help.
MATERIAL_PROPERTIES = {"E": "elastic modulus, e.g. \"115 GPa\"", "nu": "Poisson's ratio, e.g. 0.31",
                       "Sy": "yield strength, e.g. \"69 MPa\"", "rho": "density, e.g. \"8960 kg/m3\""}
#: The largest sphere diameter and plate thickness taken as a bare number [m] without --allow-implausible.
MAX_BARE_LENGTH = 0.5
#: The plate's thickness over the sphere's diameter taken without --allow-implausible when either was a bare number.
PLAUSIBLE_T_OVER_D = (0.01, 100.0)


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser whose refusals (an invalid choice, a value that is not an integer) echo the
    user's text shortened (:func:`shorten_quoted`): one short line and exit 2."""

    def error(self, message):
        super().error(shorten_quoted(message))

    def print_help(self, file=None):
        """The help on ``file``; on standard output flushed at once, so that a full disk or a closed pipe
        is one line and exit 74 (or a quiet 141), not an exception at the interpreter's exit."""
        if file is not None:
            return super().print_help(file)
        from .output_files import finish_stdout

        status = finish_stdout(self.prog, self.format_help().rstrip("\n"))
        if status:
            self.exit(status)
        return None


def add_material_options(parser, role: str, required_help: str = "") -> None:
    """``--ROLE KEY``, ``--ROLE-material FILE.toml`` and ``--ROLE-E/-nu/-Sy/-rho`` on ``parser``."""
    group = parser.add_argument_group(f"{role} material", f"a preset (--{role}), a TOML file (--{role}-material) "
                                      f"or the four properties; each property given overrides the preset's or "
                                      f"the file's{required_help}")
    group.add_argument(f"--{role}", metavar="KEY", help=f"{role} material preset (restitution materials)")
    group.add_argument(f"--{role}-material", metavar="FILE", help="TOML file: E, nu, Sy, rho (a number in SI or "
                       "a string with its unit) and optionally name, source")
    for key, what in MATERIAL_PROPERTIES.items():
        group.add_argument(f"--{role}-{key}", metavar="VALUE", dest=f"{role}_{key}", help=f"{role} {what}")


#: The rule, for --help epilogs.
BARE_NUMBER_RULE = ("A bare number is SI (metres, Pa, kg/m3, m/s): a bare sphere diameter or plate thickness over "
                    f"{MAX_BARE_LENGTH:g} m, or t/d outside {PLAUSIBLE_T_OVER_D[0]:g} to {PLAUSIBLE_T_OVER_D[1]:g} "
                    "with a bare length, is refused as a likely slip (\"--d 10\" meant 10 mm); write the unit "
                    "(\"10 m\") or give --allow-implausible to accept it.")


def add_impact_options(parser, speed_required: bool = True) -> None:
    """``--d``, ``--t``, ``--v`` (required unless not ``speed_required``), ``--edge``, ``--allow-implausible``
    and the sphere's and the plate's material options (:func:`add_material_options`) on ``parser``."""
    parser.add_argument("--d", required=True, metavar="LEN", help="sphere diameter, e.g. \"6.35 mm\" (a bare "
                                                                  "number is metres)")
    parser.add_argument("--t", required=True, metavar="LEN", help="plate thickness, e.g. \"3 mm\" (a bare number "
                                                                  "is metres)")
    parser.add_argument("--v", required=speed_required, metavar="SPEED", help="approach speed, e.g. \"2 m/s\"")
    parser.add_argument("--edge", metavar="LEN", help="distance from the impact point to the plate's nearest "
                                                      "edge, e.g. \"76 mm\" (default: an unbounded plate)")
    parser.add_argument("--allow-implausible", action="store_true",
                        help="accept a bare-number length that looks like a slip (a 10 m sphere)")
    add_material_options(parser, "sphere")
    add_material_options(parser, "plate")
