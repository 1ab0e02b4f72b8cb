"""The documentation site (docs/conf.py): it builds with warnings as errors, every Markdown page of
docs/ is a page of it, the API reference shows the units of ImpactResult's fields and of the
equations' arguments, and every recipe of examples/gallery/ ran and has its page.

The site is built once, from a copy of docs/ and examples/gallery/ in a temporary folder (sphinx-gallery
writes its pages into the source folder; the checkout stays untouched), the way CI builds it:
``python -m sphinx -W --keep-going -b html docs OUT``. The FMU recipes build their FMUs themselves.
"""
import dataclasses
import html
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

import restitution as r

for _module in ("sphinx", "myst_parser", "numpydoc", "sphinx_gallery"):
    pytest.importorskip(_module, reason=f"{_module} is not installed: the documentation site needs the "
                                        "docs extra (pip install -e '.[docs]')")

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
GALLERY = ROOT / "examples" / "gallery"
RECIPES = sorted(p.stem for p in GALLERY.glob("*.py"))
PAGES = sorted(p.stem for p in DOCS.glob("*.md"))


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The built site's folder (the build's output is in the failure message)."""
    work = tmp_path_factory.mktemp("docs_site")
    # what a build in the checkout generates is left out: the copy builds as a clean checkout does
    shutil.copytree(DOCS, work / "docs", ignore=shutil.ignore_patterns("gallery", "_build", "sg_execution_times.rst",
                                                                       "__pycache__"))
    shutil.copytree(GALLERY, work / "examples" / "gallery", ignore=shutil.ignore_patterns("__pycache__"))
    out = work / "html"
    env = {key: value for key, value in os.environ.items() if key != "RESTITUTION_GALLERY_FMUS"}
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           str(work / "docs"), str(out)], capture_output=True, text=True, env=env, timeout=900)
    elapsed = time.perf_counter() - start
    assert proc.returncode == 0, f"sphinx-build failed ({proc.returncode}):\n{proc.stdout[-4000:]}\n{proc.stderr[-8000:]}"
    print(f"documentation site built in {elapsed:.1f} s")
    return out


def _text(page: Path) -> str:
    """A page's text without its tags, entities resolved."""
    return html.unescape(re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8")))


def _entry(page: Path, anchor: str) -> str:
    """The text of the API entry with the HTML id ``anchor``: from its signature to the next entry's."""
    source = page.read_text(encoding="utf-8")
    start = source.index(f'id="{anchor}"')
    following = source.find('<dt class="sig', start + 1)
    return html.unescape(re.sub(r"<[^>]+>", "", source[start:following if following > 0 else None]))


def test_landing_page_lists_every_markdown_page(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    for page in PAGES:
        if page == "index":
            continue
        assert (site / f"{page}.html").is_file(), f"docs/{page}.md is not a page of the site"
        assert f'href="{page}.html"' in index, f"the landing page does not link to {page}"
    for target in ("api/index.html", "gallery/index.html"):
        assert f'href="{target}"' in index


def test_markdown_links_between_pages_resolve(site):
    # a relative .md link and a link to a section of another page (docs/hosts.md -> host_contract.md#...)
    hosts = (site / "hosts.html").read_text(encoding="utf-8")
    assert 'href="host_contract.html"' in hosts
    anchors = re.findall(r'href="host_contract\.html#([^"]+)"', hosts)
    assert anchors, "hosts.md links to a section of host_contract.md"
    contract = (site / "host_contract.html").read_text(encoding="utf-8")
    for anchor in anchors:
        assert f'id="{anchor}"' in contract, f"host_contract.html has no section #{anchor}"


def test_impact_result_fields_show_their_units(site):
    page = site / "api" / "restitution.html"
    assert "[m/s]" in _entry(page, "restitution.ImpactResult.v_rebound")
    for field in dataclasses.fields(r.ImpactResult):
        entry = _entry(page, f"restitution.ImpactResult.{field.name}")
        if field.type == "Real":  # a number: its unit in brackets ([1] for a dimensionless one)
            assert re.search(r"\[[^\]]+\]", entry), f"ImpactResult.{field.name} shows no unit: {entry!r}"
        else:  # a flag: what it says
            assert len(entry.split()) > 2, f"ImpactResult.{field.name} is not described: {entry!r}"


def test_bodies_and_materials_show_their_units(site):
    page = site / "api" / "restitution.html"
    assert "[m]" in _entry(page, "restitution.Sphere.d")
    assert "[m]" in _entry(page, "restitution.Plate.t")
    for name in ("E", "Sy"):
        assert "[Pa]" in _entry(page, f"restitution.Material.{name}")


def test_equation_arguments_show_their_units(site):
    # the arguments' units come from restitution.quantities.with_units (docs/units_in_docs.py)
    entry = _entry(site / "api" / "equations.html", "restitution.effective_modulus")
    for argument, unit in r.effective_modulus.si_units.items():
        shown = "1" if unit == "dimensionless" else unit
        assert f"{argument} [{shown}]" in entry


def test_api_reference_covers_the_public_api(site):
    api = site / "api"
    expected = {
        "restitution.html": ["restitution.impact", "restitution.impact_between", "restitution.ImpactResult",
                             "restitution.Material", "restitution.Sphere", "restitution.Plate", "restitution.MATERIALS"],
        "equations.html": ["restitution.effective_modulus", "restitution.restitution_e45", "restitution.zener_restitution",
                           "restitution.apparent_restitution"],
        "fit.html": ["restitution.fit.fit", "restitution.fit.Calibration"],
        "cosim.html": ["restitution.cosim.FmuInstance", "restitution.cosim.bounce", "restitution.cosim.package_rebound",
                       "restitution.cosim.fmu_rebound"],
        "sweep.html": ["restitution.sweep.run_sweep", "restitution.sweep.SweepSpec"],
        "assumptions.html": ["restitution.assumptions.departures", "restitution.assumptions.AssumptionWarning"],
    }
    for page, anchors in expected.items():
        source = (api / page).read_text(encoding="utf-8")
        for anchor in anchors:
            assert f'id="{anchor}"' in source, f"{anchor} is not documented in api/{page}"


def test_every_recipe_ran_and_has_its_page(site):
    gallery = site / "gallery"
    index = (gallery / "index.html").read_text(encoding="utf-8")
    assert len(RECIPES) >= 6
    for recipe in RECIPES:
        page = gallery / f"{recipe}.html"
        assert page.is_file(), f"examples/gallery/{recipe}.py has no page"
        assert f'href="{recipe}.html"' in index
        source = page.read_text(encoding="utf-8")
        assert "sphx-glr-script-out" in source, f"{recipe}: no printed output (did it run?)"
        if recipe.startswith("plot_"):
            figure = f"sphx_glr_{recipe}_001.png"
            assert figure in source and (site / "_images" / figure).is_file(), f"{recipe}: no figure"


def test_fmu_recipes_print_the_cor_of_the_package(site):
    # the FMUs' e at 2.3 m/s is the package's, to the 4 digits printed (chrome steel d = 4.76 mm on brass t = 3.18 mm)
    ball = r.Sphere(r.MATERIALS["chrome_steel"], 4.76e-3)
    plate = r.Plate(r.MATERIALS["brass_260"], 3.18e-3)
    expected = f"e = {r.impact_between(ball, plate, v=2.3).e:.4f}"
    for recipe in ("fmi2_fmu_in_fmpy", "fmi3_fmu_in_fmpy"):
        lines = [line for line in _text(site / "gallery" / f"{recipe}.html").splitlines() if "v = 2.3 m/s" in line]
        assert lines and expected in lines[0], f"{recipe}: {lines}"


# --- the layout: code blocks stay inside the content column (a headless chromium at 1280 px) ------------
CHROMIUM = Path("/usr/bin/chromium")
WINDOW = (1280, 900)
#: Run at the page's load: every code block's box, its scrolling and the content column's box, written into
#: the DOM as JSON (chromium --dump-dom prints the DOM after the scripts ran).
LAYOUT_PROBE = """
window.addEventListener("load", function () {
  var main = document.querySelector("article[role=main]") || document.querySelector("div.body") || document.body;
  var col = main.getBoundingClientRect();
  function scroller(el) {  // el or its nearest ancestor inside the column that scrolls sideways
    for (var e = el; e && e !== main.parentElement; e = e.parentElement) {
      var x = getComputedStyle(e).overflowX;
      if (x === "auto" || x === "scroll") return e;
    }
    return null;
  }
  var blocks = Array.prototype.map.call(main.querySelectorAll("pre"), function (pre) {
    var r = pre.getBoundingClientRect(), s = getComputedStyle(pre), sc = scroller(pre);
    var q = sc ? sc.getBoundingClientRect() : null;
    return {line: pre.textContent.split("\\n")[0].slice(0, 100), left: r.left, right: r.right, width: r.width,
            scrollWidth: pre.scrollWidth, clientWidth: pre.clientWidth, whiteSpace: s.whiteSpace,
            bar: pre.offsetHeight - pre.clientHeight - parseFloat(s.borderTopWidth) - parseFloat(s.borderBottomWidth),
            scroller: sc ? sc.tagName.toLowerCase() : null, scrollerRight: q ? q.right : null,
            scrollerScrollWidth: sc ? sc.scrollWidth : null, scrollerClientWidth: sc ? sc.clientWidth : null};
  });
  var out = document.createElement("script");
  out.type = "application/json";
  out.id = "layout-report";
  out.textContent = JSON.stringify({innerWidth: window.innerWidth, pageScrollWidth: document.documentElement.scrollWidth,
    column: {left: col.left, right: col.right}, blocks: blocks}).replace(/</g, "\\\\u003c");
  document.body.appendChild(out);
});
"""


def _long_code_pages(limit: int = 80) -> list[str]:
    """The pages of docs/ with a code line longer than ``limit`` characters, getting started first."""
    pages = []
    for page in [DOCS / "getting_started.md", DOCS / "hosts.md"] + sorted(DOCS.glob("*.md")):
        blocks = re.findall(r"(?ms)^```[^\n{]*\n(.*?)^```", page.read_text(encoding="utf-8"))
        if page.stem not in pages and any(len(line) > limit for block in blocks for line in block.splitlines()):
            pages.append(page.stem)
    return pages


def _chromium(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    profile = cwd / "chromium-profile"
    return subprocess.run([str(CHROMIUM), "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                           f"--user-data-dir={profile}",
                           f"--window-size={WINDOW[0]},{WINDOW[1]}", "--run-all-compositor-stages-before-draw",
                           "--virtual-time-budget=10000", *args], capture_output=True, text=True, timeout=120, cwd=cwd)


def _layout(site: Path, page: str, work: Path) -> dict:
    """What LAYOUT_PROBE measured on ``page`` (a copy beside it, so that its stylesheets load)."""
    source = (site / f"{page}.html").read_text(encoding="utf-8")
    probe = site / f"{page}.layout-probe.html"
    probe.write_text(source.replace("</body>", f"<script>{LAYOUT_PROBE}</script></body>"), encoding="utf-8")
    proc = _chromium(["--dump-dom", probe.as_uri()], work)
    found = re.search(r'<script type="application/json" id="layout-report">(.*?)</script>', proc.stdout, re.S)
    assert found, f"chromium measured nothing on {page} (exit {proc.returncode}):\n{proc.stderr[-2000:]}"
    return json.loads(found.group(1))


@pytest.mark.skipif(not CHROMIUM.is_file(), reason="no /usr/bin/chromium (Debian's chromium; "
                                                   "build_scripts/system_packages.sh installs it)")
def test_code_blocks_stay_inside_the_column(site, tmp_path):
    """At 1280 px, on every page with a code line longer than 80 characters: no code block runs past the
    content column's right edge, nor the window's; a block whose lines are wider than it scrolls sideways
    inside the column, with a scrollbar drawn (it takes height: not an overlay that shows only while
    scrolling), or wraps. A screenshot of the getting-started page is kept beside the test's files."""
    pages = _long_code_pages()
    assert "getting_started" in pages and len(pages) >= 3, pages
    overflowing, problems = 0, []
    for page in pages:
        report = _layout(site, page, tmp_path)
        assert report["innerWidth"] == WINDOW[0], report["innerWidth"]
        right = report["column"]["right"]
        if report["pageScrollWidth"] > WINDOW[0] + 1:
            problems.append(f"{page}: the page is {report['pageScrollWidth']} px wide in a {WINDOW[0]} px window")
        if right > WINDOW[0] + 1:
            problems.append(f"{page}: the content column ends at {right} px, past the window")
        assert report["blocks"], f"{page}: no code block measured"
        for block in report["blocks"]:
            if block["width"] == 0:  # not displayed (a collapsed section): nothing to see
                continue
            where = f"{page}: the code block {block['line']!r}"
            wider = block["scrollWidth"] > block["clientWidth"] + 1
            if block["right"] > right + 1 and (block["scrollerRight"] is None or block["scrollerRight"] > right + 1):
                problems.append(f"{where} ends at {block['right']:.0f} px, past the column's {right:.0f} px")
            if wider:
                overflowing += 1
                if block["scroller"] is None and "wrap" not in block["whiteSpace"]:
                    problems.append(f"{where} is {block['scrollWidth']} px wide in {block['clientWidth']} px and "
                                    "neither scrolls nor wraps: its end is cut off")
                elif block["scroller"] == "pre" and block["bar"] <= 0:
                    problems.append(f"{where} scrolls with no scrollbar drawn: its end looks cut off")
    assert not problems, "\n".join(problems)
    assert overflowing >= 3, "no page measured has a code line wider than its column: the test tests nothing"
    shot = tmp_path / "getting_started.png"
    proc = _chromium([f"--screenshot={shot}", (site / "getting_started.html").as_uri()], tmp_path)
    assert shot.is_file() and shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", proc.stderr[-2000:]
    assert int.from_bytes(shot.read_bytes()[16:20], "big") == WINDOW[0]  # the PNG's width
