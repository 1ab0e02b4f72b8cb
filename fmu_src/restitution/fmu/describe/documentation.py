"""The documentation every FMU carries, where FMI 2.0 and 3.0 put it:

* ``documentation/index.html``, the entry point of an FMU's documentation (what a tool's documentation
  button opens): the model's name, version and description, every variable of the FMU (grouped by
  causality, with its type, unit, start value, the range this FMU accepts and its description), the
  model's equations, assumptions and validity, how to cite it and a link to the license. Written by
  :func:`index_html` from the model's interface table (``models/<model>/variables.py``: the same rows
  the modelDescription is written from) and the model's prose (``models/<model>/documentation.py``:
  ``DOCUMENTATION``, a tuple of
  :class:`restitution.fmu.models.text.Section`), for one implementation: the pythonfmu FMU (FMI 2.0
  co-simulation) or a native one (FMI 2.0 or 3.0, co-simulation and model exchange, the native ranges
  where the table gives ``native_interval``). Self-contained XHTML (inline CSS, no script, nothing
  fetched), every text escaped, and nothing that changes between builds (no date), so two builds write
  the same file.

The license files beside it (``documentation/licenses/``) are the build's
(:mod:`restitution.fmu.builders.licenses`). Pure data in, text out.
"""
from __future__ import annotations

import html
import importlib
import re

from ...about import COPYRIGHT, LICENSE, VERSION
from ..models import FOLDERS, table as _table
from ..models.text import Rows, Section
from .common import limit_text
from .fmi3 import ELEMENTS as FMI3_TYPES, TIME_NAME, TIME_UNIT

__all__ = ["INDEX", "index_html", "model_documentation", "CITATIONS"]

#: The entry point of an FMU's documentation (FMI 2.0 and 3.0).
INDEX = "documentation/index.html"


def model_documentation(model: str) -> tuple[Section, ...]:
    """The prose of ``model``: ``DOCUMENTATION`` of ``models/<model>/documentation.py``."""
    return importlib.import_module(f"{_table.__module__}.{FOLDERS[model]}.documentation").DOCUMENTATION


#: The citation of every FMU: the software, then the paper it implements (the preferred citation) and
#: the two models that paper fuses, as CITATION.cff gives them.
CITATIONS = (
    "I. Green, The prediction of the coefficient of restitution between impacting spheres and finite thickness "
    "plates undergoing elastoplastic deformations and wave propagation, Nonlinear Dynamics (2022). The model this "
    "project implements: cite it (the preferred citation).",
    "R. L. Jackson, I. Green, D. B. Marghitu, Predicting the coefficient of restitution of impacting "
    "elastic-perfectly plastic spheres, Nonlinear Dynamics 60(3):217-229 (2010). The JGM model.",
    "C. Zener, The intrinsic inelasticity of large plates, Physical Review 59(8):669-673 (1941). Zener's model.",
)

#: What each implementation is, for the section "This FMU": (FMI version, native) -> paragraphs.
IMPLEMENTATIONS = {
    ("2.0", False): (
        "The pythonfmu FMU: FMI 2.0 co-simulation. Its model is the restitution Python package, bundled in "
        "`resources/` and run by pythonfmu (the reference implementation, which the native FMUs follow). It runs in "
        "Python hosts (fmpy, libcosimpy, ...). Where the build had gcc, its Linux binary is the project's C front "
        "in front of pythonfmu: it checks every FMI call before Python sees it, and starts the Python the FMU was "
        "built with in plain C hosts.",
    ),
    ("2.0", True): (
        "The native FMI 2.0 FMU: co-simulation and model exchange from one binary, the project's C front and the "
        "model in C99 (the C library and libm only, no Python at run time). `binaries/` holds the platforms the "
        "build had a compiler for (linux64 with gcc; win64 with mingw-w64 or zig; darwin64, one file for Intel and "
        "Apple silicon Macs, with zig); other platforms compile `sources/`.",
    ),
    ("3.0", True): (
        "The native FMI 3.0 FMU: co-simulation and model exchange from one binary, the project's C front and the "
        "model in C99 (the C library and libm only, no Python at run time). `binaries/` holds the platforms the "
        "build had a compiler for (x86_64-linux with gcc; x86_64-windows with mingw-w64 or zig; aarch64-linux, "
        "x86_64-darwin and aarch64-darwin with zig); other platforms compile `sources/` (`sources/buildDescription.xml`).",
        "FMI 3.0 types: Reals are Float64; the choices are Enumerations with named items, got and set with "
        "fmi3GetInt64 and fmi3SetInt64; `time` is the independent variable, read-only.",
    ),
}

#: The variable groups of the table, in order: (heading, causality).
GROUPS = (("Inputs", "input"), ("Parameters", "parameter"), ("Calculated parameters", "calculatedParameter"),
          ("Outputs", "output"), ("Local variables", "local"))

STYLE = """
body { font-family: sans-serif; line-height: 1.45; max-width: 72em; margin: 1.5em auto; padding: 0 1em;
       color: #1a1a1a; background: #fff; }
h1 { margin-bottom: 0.2em; }
h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.15em; margin-top: 1.6em; }
p.subtitle { color: #555; margin-top: 0; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; width: 100%; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.45em; text-align: left; vertical-align: top; }
th { background: #f0f0f0; }
tr:nth-child(even) td { background: #fafafa; }
td.name, td.unit, td.start, td.range { white-space: nowrap; }
code, td.name { font-family: monospace; }
td.range { white-space: normal; min-width: 10em; }
span.role { font-style: italic; }
nav ul { columns: 2; }
"""


# --- writing ---

def _esc(text, attribute: bool = False) -> str:
    """``text`` escaped for an element (&, <, >) or, ``attribute``, for a quoted attribute value."""
    return html.escape(str(text), quote=attribute)


def _inline(text: str) -> str:
    """Plain text, escaped, with `backticked` parts as <code>."""
    parts = text.split("`")
    if len(parts) % 2 == 0:
        raise ValueError(f"unbalanced backticks in documentation text: {text!r}")
    return "".join(f"<code>{_esc(part)}</code>" if i % 2 else _esc(part) for i, part in enumerate(parts))


def _slug(title: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-")


def _number(value) -> str:
    """The shortest text (%g style) that reads back as the same double."""
    value = float(value)
    for digits in range(1, 18):
        text = f"{value:.{digits}g}"
        if float(text) == value:
            return text
    return repr(value)


def _fmi_type(row, fmi_version: str) -> str:
    """The variable's type as this FMU's modelDescription declares it."""
    if fmi_version == "3.0":
        return "Enumeration" if row.is_enumeration else FMI3_TYPES[row.type]
    return "Enumeration" if row.enumeration is not None else row.type


def _range(row, low: str | None, high: str | None) -> str:
    """What this FMU accepts: the choices in range, or the interval, bounds as the modelDescription has them."""
    if row.choices is not None:
        codes = [(code, word) for word, code in row.codes.items()
                 if (low is None or code >= int(low)) and (high is None or code <= int(high))]
        return ", ".join(f"{code} = {word}" for code, word in codes)
    if low is not None and high is not None:
        return f"{low} \u2264 value \u2264 {high}"
    if low is not None:
        return f"value \u2265 {low}, finite"
    if high is not None:
        return f"value \u2264 {high}, finite"
    return "any finite value"


def _start(row) -> str:
    if row.causality not in ("parameter", "input") or row.start is None:
        return ""
    if row.type == "Boolean":
        return "true" if row.start else "false"
    if row.choices is not None:
        return f"{int(row.start)} = {row.word(row.start)}"
    if row.type == "Integer":
        return str(int(row.start))
    return _number(row.start)


def _roles(row, model_table, model_exchange: bool) -> list[str]:
    """What a variable is to a model-exchange host (its state vector, derivatives, event indicators)."""
    if not model_exchange:
        return []
    roles = []
    if row in model_table.continuous_states:
        derivative = next(d.name for d in model_table.derivatives if d.derivative == row.name)
        roles.append(f"Continuous state (model exchange; its derivative is {derivative}).")
    if row.derivative is not None:
        roles.append(f"Derivative of the continuous state {row.derivative} (model exchange).")
    if row.event_indicator:
        roles.append("Event indicator (model exchange).")
    return roles


def _narrower(row, native: bool) -> str | None:
    """A note where this FMU accepts less than the table's full range (the native FMUs' ``native_interval``)."""
    if row.native_interval is None or not native:
        return None
    if row.choices is not None:
        low, high = row.native_interval[:2]
        missing = [f"{code} = {word}" for word, code in row.codes.items() if not low <= code <= high]
        return f"Not offered by this FMU: {', '.join(missing)} (the pythonfmu FMU does)."
    return f"The pythonfmu FMU accepts {_range(row, *row.xml_limits())}."


def _cells(name, causality, vtype, unit, start, allowed, description) -> str:
    cells = (("name", _esc(name)), ("causality", _esc(causality)), ("type", _esc(vtype)), ("unit", _esc(unit)),
             ("start", _esc(start)), ("range", _esc(allowed)), ("description", description))
    return "<tr>" + "".join(f'<td class="{cls}">{text}</td>' for cls, text in cells) + "</tr>"


def _variables(model_table, fmi_version: str, native: bool) -> list[str]:
    model_exchange = native
    header = ("<tr><th>name</th><th>causality (variability)</th><th>type</th><th>unit</th><th>start</th>"
              "<th>accepted values</th><th>description</th></tr>")
    out = []
    for heading, causality in GROUPS:
        rows = [row for row in model_table if row.causality == causality]
        if not rows:
            continue
        out += [f'<h3 id="{_slug(heading)}">{_esc(heading)}</h3>', '<table class="variables">', header]
        for row in rows:
            low, high = limit_text(row, native) if causality in ("parameter", "input") else (None, None)
            allowed = _range(row, low, high) if causality in ("parameter", "input") else ""
            notes = [f'<span class="role">{_esc(text)}</span> ' for text in _roles(row, model_table, model_exchange)]
            narrower = _narrower(row, native)
            text = row.description if narrower is None else f"{row.description.rstrip('.')}. {narrower}"
            description = "".join(notes) + _esc(text)
            unit = row.unit if row.type == "Real" and row.unit is not None else ""
            out.append(_cells(row.name, f"{row.causality} ({row.variability})", _fmi_type(row, fmi_version), unit,
                              _start(row), allowed, description))
        out.append("</table>")
    if fmi_version == "3.0":  # every FMI 3.0 FMU has one independent variable (describe/fmi3.py)
        out += ['<h3 id="independent-variable">Independent variable</h3>', '<table class="variables">', header,
                _cells(TIME_NAME, "independent (continuous)", FMI3_TYPES["Real"], TIME_UNIT, "", "",
                       "Simulation time: the start time until initialization ends, then the end of the last step "
                       "(co-simulation) or the time the host set (model exchange). Read-only."),
                "</table>"]
    return out


def _enumerations(model_table) -> list[str]:
    """The items of the named choices whose items the table describes (the material presets)."""
    out = []
    for name, row in model_table.enumerations.items():
        if not row.item_descriptions:
            continue
        users = ", ".join(r.name for r in model_table if r.enumeration == name)
        out += [f'<h3 id="{_slug("type " + name)}">Enumeration {_esc(name)} ({_esc(users)})</h3>',
                '<table class="items">', "<tr><th>code</th><th>item</th><th>what it is</th></tr>"]
        for (word, code), text in zip(row.codes.items(), row.item_descriptions):
            out.append(f'<tr><td class="start">{code}</td><td class="name">{_esc(word)}</td><td>{_esc(text)}</td></tr>')
        out.append("</table>")
    return out


def _block(block) -> list[str]:
    if isinstance(block, str):
        return [f"<p>{_inline(block)}</p>"]
    if isinstance(block, Rows):
        lines = ["<table>", "<tr>" + "".join(f"<th>{_inline(cell)}</th>" for cell in block.header) + "</tr>"]
        for row in block.rows:
            if len(row) != len(block.header):
                raise ValueError(f"a row of {len(row)} cells under a header of {len(block.header)}: {row!r}")
            lines.append("<tr>" + "".join(f"<td>{_inline(cell)}</td>" for cell in row) + "</tr>")
        return lines + ["</table>"]
    if isinstance(block, tuple):
        return ["<ul>", *(f"<li>{_inline(item)}</li>" for item in block), "</ul>"]
    raise TypeError(f"a documentation block is a str, a tuple of str or Rows, not {type(block).__name__}")


def index_html(model: str, fmi_version: str = "2.0", native: bool = False) -> str:
    """``documentation/index.html`` of ``model``'s pythonfmu FMU (``native`` False: FMI 2.0 co-simulation)
    or native FMU of ``fmi_version`` (co-simulation and model exchange, the native ranges)."""
    if (fmi_version, native) not in IMPLEMENTATIONS:
        raise ValueError(f"no {'native' if native else 'pythonfmu'} FMU of FMI {fmi_version}")
    model_table = _table(model)
    prose = [section for section in model_documentation(model)
             if section.model_exchange is None or section.model_exchange == native]
    identity = "instantiationToken" if fmi_version == "3.0" else "GUID"
    interfaces = "co-simulation and model exchange" if native else "co-simulation"
    sections = [("This FMU", [
        *(f"<p>{_inline(text)}</p>" for text in IMPLEMENTATIONS[(fmi_version, native)]),
        "<ul>",
        f"<li>Model identifier: <code>{_esc(model)}</code>; FMI {_esc(fmi_version)}, {_esc(interfaces)}.</li>",
        f"<li>Version: restitution {_esc(VERSION)}.</li>",
        f"<li>{identity}: <code>{_esc(model_table.instantiation_token(VERSION))}</code>, the same in the pythonfmu, "
        "native FMI 2.0 and native FMI 3.0 FMUs of this model and version, and in every build of them.</li>",
        "<li>What a host sees for every mistake (refused calls and values, what is logged), the FMU states and the "
        "threading rules: <code>docs/host_contract.md</code> in the source distribution.</li>",
        "</ul>"])]
    sections += [(section.title, [line for block in section.blocks for line in _block(block)]) for section in prose]
    sections.append(("Variables", [
        "<p>Every variable of this FMU, as its <code>modelDescription.xml</code> declares it. Accepted values are "
        "what a set call takes, bounds included (the declared <code>min</code> and <code>max</code>); anything "
        "else is refused with an error and the previous value kept.</p>",
        *_variables(model_table, fmi_version, native), *_enumerations(model_table)]))
    sections.append(("Citation", [
        f"<p>Cite the software as restitution developers, restitution {_esc(VERSION)} ({_esc(LICENSE)} license; "
        "<code>CITATION.cff</code> in the source distribution), together with the paper it implements and the two "
        "models that paper fuses:</p>",
        "<ul>", *(f"<li>{_inline(text)}</li>" for text in CITATIONS), "</ul>"]))
    license_links = ['<a href="licenses/license.txt">licenses/license.txt</a>']
    if not native:
        license_links.append('<a href="licenses/pythonfmu.txt">licenses/pythonfmu.txt</a> (pythonfmu, which this '
                             "FMU bundles, MIT)")
    sections.append(("License", [
        f"<p>{_esc(COPYRIGHT)}. Released under the {_esc(LICENSE)} license, whose notice travels with every copy: "
        f"{', and '.join(license_links)}.</p>"]))

    lines = ['<!DOCTYPE html>', '<html xmlns="http://www.w3.org/1999/xhtml" lang="en" xml:lang="en">', "<head>",
             '<meta charset="utf-8"/>', f"<title>{_esc(model)} {_esc(VERSION)}</title>",
             f'<meta name="description" content="{_esc(model_table.description, attribute=True)}"/>',
             f"<style>{STYLE}</style>", "</head>", "<body>",
             f"<h1>{_esc(model)}</h1>",
             f'<p class="subtitle">restitution {_esc(VERSION)} \u00b7 FMI {_esc(fmi_version)} {_esc(interfaces)} '
             f"\u00b7 {'native (C)' if native else 'pythonfmu (Python)'}</p>",
             f"<p>{_esc(model_table.description)}.</p>",
             '<nav><ul>', *(f'<li><a href="#{_slug(title)}">{_esc(title)}</a></li>' for title, _ in sections),
             "</ul></nav>"]
    for title, body in sections:
        lines += [f'<h2 id="{_slug(title)}">{_esc(title)}</h2>', *body]
    lines += ["</body>", "</html>"]
    if len({_slug(title) for title, _ in sections}) != len(sections):
        raise ValueError(f"{model}: two documentation sections share a title")
    return "\n".join(lines) + "\n"

