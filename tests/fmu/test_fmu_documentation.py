"""Every FMU carries ``documentation/index.html``, the entry point of an FMU's documentation in FMI 2.0 and
3.0 (what a tool's documentation button opens), and it documents that FMU: checked against the FMU's own
modelDescription.xml as fmpy reads it, not against the interface table the page is written from.

* It is well-formed XHTML (xml.etree parses it), self-contained (no script, no external style sheet,
  image or frame; every link goes to an anchor of the page or to a file of the archive, the license
  among them) and every id is unique.
* Every variable of the modelDescription has one row, with its causality, type, unit, start value and
  its declared min and max as the accepted values, and its description; the page lists no variable
  the modelDescription does not declare.
* It states the model's name, description, version and GUID (instantiation token) as the
  modelDescription does, its equations and validity, the citation of CITATION.cff, and the
  model-exchange section exactly where the FMU offers model exchange.
* The page is the same in every render (no date, nothing from the process), and the built file is it.
"""
import hashlib
import math
import os
import posixpath
import re
import subprocess
import sys
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

ROOT = Path(__file__).resolve().parents[2]
INDEX = "documentation/index.html"
XHTML = "{http://www.w3.org/1999/xhtml}"
#: fixture -> (model, FMI version, native), the arguments of restitution.fmu.describe.documentation.index_html
FMUS = {
    "impact_fmu": ("SpherePlateImpact", "2.0", False),
    "ball_fmu": ("BouncingBall", "2.0", False),
    "native_impact_fmu": ("SpherePlateImpact", "2.0", True),
    "native_ball_fmu": ("BouncingBall", "2.0", True),
    "fmi3_impact_fmu": ("SpherePlateImpact", "3.0", True),
    "fmi3_ball_fmu": ("BouncingBall", "3.0", True),
}
#: A number standing alone (not the digits of a word such as e45 or al_6061).
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?(?![\w.])")
#: What the page never contains: a date or time of the build.
DATE = re.compile(r"\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}")


def _tag(element) -> str:
    return element.tag.removeprefix(XHTML)


def _text(element) -> str:
    return " ".join("".join(element.itertext()).split())


@pytest.fixture(params=list(FMUS))
def fmu(request):
    """(path, model, FMI version, native, the page's bytes, the archive's names) of each built FMU."""
    path = request.getfixturevalue(request.param)
    with zipfile.ZipFile(path) as z:
        names = set(z.namelist())
        assert INDEX in names, f"{path}: no {INDEX}"
        data = z.read(INDEX)
    return (path, *FMUS[request.param], data, names)


def _page(data: bytes) -> ET.Element:
    root = ET.fromstring(data)  # well-formed, or ParseError
    assert _tag(root) == "html"
    assert [_tag(child) for child in root] == ["head", "body"]
    return root


def _variable_rows(root) -> dict[str, dict[str, str]]:
    """name -> {cell class: text} of every row of the variable tables."""
    rows = {}
    for table in root.iter(f"{XHTML}table"):
        if table.get("class") != "variables":
            continue
        for tr in table.iter(f"{XHTML}tr"):
            cells = {td.get("class"): _text(td) for td in tr if _tag(td) == "td"}
            if not cells:
                continue  # the header
            assert cells["name"] not in rows, f"{cells['name']} listed twice"
            rows[cells["name"]] = cells
    return rows


def test_the_page_is_well_formed_and_self_contained(fmu):
    path, _model, _version, _native, data, names = fmu
    root = _page(data)
    text = data.decode("utf-8")
    assert root.find(f"{XHTML}head/{XHTML}meta").get("charset") == "utf-8"
    assert not any(_tag(e) in ("script", "link", "img", "iframe", "object", "embed") for e in root.iter())
    assert not any(e.get("src") or e.get("style") or any(a.startswith("on") for a in e.attrib) for e in root.iter())
    assert "url(" not in text and "@import" not in text
    ids = [e.get("id") for e in root.iter() if e.get("id") is not None]
    assert len(ids) == len(set(ids)), "an id is used twice"
    links = [a.get("href") for a in root.iter(f"{XHTML}a")]
    assert "licenses/license.txt" in links
    for href in links:
        assert "://" not in href and not href.startswith(("/", "mailto:")), href
        if href.startswith("#"):
            assert href[1:] in ids, f"{path.name}: no anchor {href}"
        else:
            assert posixpath.normpath(posixpath.join(posixpath.dirname(INDEX), href)) in names, \
                f"{path.name}: {href} is not a file of the archive"
    assert not DATE.search(text), "the page states a date"


def test_every_variable_of_the_model_description_has_its_row(fmu):
    """Unit, causality, type, start and the declared min and max, from fmpy's reading of the FMU."""
    from fmpy import read_model_description

    path, _model, _version, _native, data, _names = fmu
    rows = _variable_rows(_page(data))
    variables = read_model_description(str(path)).modelVariables
    assert sorted(rows) == sorted(v.name for v in variables)
    for v in variables:
        row = rows[v.name]
        where = f"{path.parent.name}/{path.name} {v.name}"
        assert row["causality"].split()[0] == v.causality, where
        assert f"({v.variability})" in row["causality"], where
        assert row["type"] == v.type, where
        unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
        assert row["unit"] == (unit or ""), where
        assert " ".join(v.description.split()) in row["description"], where
        numbers = [float(n) for n in NUMBER.findall(row["range"])]
        if v.min is None and v.max is None:  # an output, a local, ...: nothing to set; a settable one: unbounded
            assert row["range"] == ("any finite value" if v.causality in ("parameter", "input") else ""), where
        if v.min is not None:
            assert numbers and numbers[0] == float(v.min), f"{where}: min {v.min} is not {row['range']!r}"
        if v.max is not None:
            assert numbers and numbers[-1] == float(v.max), f"{where}: max {v.max} is not {row['range']!r}"
        if v.type in ("Real", "Float64"):  # an interval: exactly its declared bounds
            assert numbers == [float(b) for b in (v.min, v.max) if b is not None], f"{where}: {row['range']!r}"
            if v.min is not None and v.max is None:
                assert "\u2265" in row["range"] and "\u2264" not in row["range"], where
        if v.start is None:
            assert row["start"] == "", where
        elif v.type == "Boolean":
            assert row["start"] == str(v.start).lower(), where
        else:
            # pythonfmu writes some starts with 16 digits (9.806649999999999 for 9.80665): equal to 1e-12
            assert math.isclose(float(NUMBER.findall(row["start"])[0]), float(v.start), rel_tol=1e-12), where


def test_the_page_states_what_the_model_description_and_the_citation_say(fmu):
    from fmpy import read_model_description

    path, model, version, native, data, _names = fmu
    md = read_model_description(str(path))
    root = _page(data)
    text = _text(root.find(f"{XHTML}body"))
    assert md.modelName == model and _text(root.find(f"{XHTML}body/{XHTML}h1")) == model
    assert " ".join(md.description.split()) in text
    assert f"restitution {md.version}" in text and f"FMI {md.fmiVersion}" in text
    assert md.guid in text  # FMI 3.0: the instantiation token
    headings = [_text(h) for h in root.iter(f"{XHTML}h2")]
    for heading in ("What it computes", "Assumptions and validity", "Variables", "Citation", "License"):
        assert heading in headings
    assert ("Model exchange" in headings) == (md.modelExchange is not None)
    if model == "SpherePlateImpact":
        for eq in ("Eq. (1)", "Eq. (2)", "Eq. (3)", "Eqs. (4)\u2013(6)", "Eqs. (7), (8)", "Eq. (9)",
                   "Eqs. (10), (11)", "Eqs. (13), (13a)", "Eq. (12)", "Eq. (19)", "Eq. (20)", "Eq. (17)"):
            assert eq in text, eq
        assert "e = (e_ep + e_ze + e_ep e_ze \u2212 1) / 2" in text
        assert "\u03bb \u2264 1.5" in text and "V* \u2264 1000" in text
    else:
        exchange = ("contact_indicator", "der(h)", "der(v)") if md.modelExchange is not None else ()
        for name in ("contact_mode", "v_min", "h0", "g", "e", *exchange):
            assert f"<code>{name}</code>" in data.decode("utf-8"), name
    for title in _citation_titles():
        assert title in text, title


def _citation_titles() -> list[str]:
    """The titles and journals of CITATION.cff's preferred citation and references."""
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    works = [cff["preferred-citation"], *cff["references"]]
    return [" ".join(str(work[key]).split()) for work in works for key in ("title", "journal", "year")]


def test_the_built_page_is_the_render_and_every_render_is_the_same(fmu):
    """The page in the FMU is index_html's; it is the same in another process (another string hashing),
    so two builds write the same file."""
    from restitution.fmu.describe.documentation import index_html

    _path, model, version, native, data, _names = fmu
    assert index_html(model, version, native) == index_html(model, version, native)
    assert index_html(model, version, native).encode("utf-8") == data
    code = ("import hashlib, sys; from restitution.fmu.describe.documentation import index_html; "
            "print(hashlib.sha256(index_html(sys.argv[1], sys.argv[2], sys.argv[3] == 'True').encode()).hexdigest())")
    for seed in ("1", "2"):
        done = subprocess.run([sys.executable, "-c", code, model, version, str(native)], capture_output=True,
                              text=True, check=True, env={**os.environ, "PYTHONHASHSEED": seed})
        assert done.stdout.strip() == hashlib.sha256(data).hexdigest()


def test_the_pythonfmu_fmus_link_pythonfmus_license_and_the_native_ones_do_not(fmu):
    _path, _model, _version, native, data, names = fmu
    links = [a.get("href") for a in _page(data).iter(f"{XHTML}a")]
    assert ("licenses/pythonfmu.txt" in links) == (not native) == ("documentation/licenses/pythonfmu.txt" in names)


def test_prose_text_is_escaped_and_code_marked():
    from restitution.fmu.describe.documentation import _block
    from restitution.fmu.models.text import Rows

    assert _block("a < b & `x<y`") == ["<p>a &lt; b &amp; <code>x&lt;y</code></p>"]
    assert _block(("one", "`two`")) == ["<ul>", "<li>one</li>", "<li><code>two</code></li>", "</ul>"]
    assert _block(Rows(("h",), (("c > d",),))) == ["<table>", "<tr><th>h</th></tr>", "<tr><td>c &gt; d</td></tr>",
                                                   "</table>"]
    with pytest.raises(ValueError, match="backticks"):
        _block("an `unclosed code")
