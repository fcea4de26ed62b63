"""`mechbook report` in a real browser: Debian's headless Chromium, driven by Playwright
(never allowed to fetch a browser of its own). Every page loads without console errors or
failed requests, every equation is laid out as mathematics (non-empty boxes, fractions
taller than a letter), every image loads, no element overflows its table cell or the page,
no exception's text appears anywhere, the animation runs, and the index's filters work.
Screenshots of a few pages are kept in results/test-artifacts/report/ to be looked at.

The report is built once, for a scratch tree holding lim-2031 (every part passes),
lim-2035 (a double pendulum: rods and a pivot in the animation), symon-09-01 (two errata,
long equations), symon-10-05 (identities for all tensors), symon-12-27 (steady motions:
structured answers) and toy-3.2 (a third book declared only in data). Without Chromium the
browser tests are skipped, saying why; the rest still run.

What a reader trips on is checked on every page too (issue 34): an expression shown
unsimplified says so; numbers name the parameter point they were computed at; the
animation draws the links; no absolute path; legends off the curves; no Python `True`; one
minus glyph; no formula line ending in a lone bracket.
"""

from __future__ import annotations

import json
import re
import shutil
import tempfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_books import third_book_tree

from mechbook.app.cli import main

pytestmark = pytest.mark.slow  # builds a whole report of the repository; browser checks

ROOT = Path(__file__).resolve().parents[1]
ARTIFACTS = ROOT / "results" / "test-artifacts" / "report"
CHROMIUM = Path("/usr/bin/chromium")
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
COPIED = ("lim/2031", "lim/2035", "symon/09-01", "symon/10-05", "symon/12-27")
PROBLEMS = ("lim-2031", "lim-2035", "symon-09-01", "symon-10-05", "symon-12-27", "toy-3.2")
EXCEPTION_TEXT = re.compile(r"Traceback|\b[A-Z][A-Za-z]*(?:Error|Exception)\b")


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> Path:
    tree = third_book_tree(tmp_path_factory.mktemp("tree"))
    for sub in COPIED:
        for kind in ("problems", "answers"):
            dest = tree / kind / f"{sub}.yaml"
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / kind / f"{sub}.yaml", dest)
    checked = CliRunner().invoke(main, ["--root", str(tree), "check", *PROBLEMS, "--serial"])
    assert checked.exit_code == 0, checked.output
    return tree


@pytest.fixture(scope="module")
def report(tree) -> Path:
    built = CliRunner().invoke(main, ["--root", str(tree), "report", "--serial", "--t-end",
                                      "5"])
    assert built.exit_code == 0, built.output
    out = tree / "results" / "report"
    assert f"report written to {out / 'index.html'}" in built.output
    assert f"[{len(PROBLEMS)}/{len(PROBLEMS)}]" in built.output  # progress, page by page
    return out


def pages(report: Path) -> list[Path]:
    return [report / "index.html", *sorted((report / "problems").glob("*.html"))]


def test_the_report_holds_every_problem_part_and_outcome(report):
    index = (report / "index.html").read_text(encoding="utf-8")
    assert [p.stem for p in sorted((report / "problems").glob("*.html"))] == sorted(PROBLEMS)
    for pid in PROBLEMS:
        assert f'href="problems/{pid}.html"' in index
    errata = index.split('id="errata"', 1)[1].split('id="unsupported"', 1)[0]
    assert "e-Qu" in errata and "e-Qw" in errata
    assert 'data-book="toy"' in index and "A Toy Book of Oscillators" in index
    page = (report / "problems" / "symon-09-01.html").read_text(encoding="utf-8")
    assert page.count("corrected value:</p><div") + page.count("corrected value:</p><math") \
        == 2 and "the erratum's derivation" in page
    toy = (report / "problems" / "toy-3.2.html").read_text(encoding="utf-8")
    assert toy.count("<math") >= 6 and 'class="animation"' in toy and "<svg" in toy
    for page in pages(report):  # offline: nothing is fetched from elsewhere
        text = page.read_text(encoding="utf-8")
        for allowed in ("http://www.w3.org/1998/Math/MathML", "http://www.w3.org/2000/svg"):
            text = text.replace(allowed, "")
        assert "http://" not in text and "https://" not in text


def test_the_book_and_the_engine_side_by_side(report):
    """Each part of the toy problem shows the book's value and the engine's, the engine's
    from the check's stored linear system (its own sqrt(k/m); at one point both 2)."""
    toy = (report / "problems" / "toy-3.2.html").read_text(encoding="utf-8")
    parts = toy.split('<section class="part" id="part-')[1:]
    assert [p.split('"', 1)[0] for p in parts] == ["a", "b", "c"]
    for part in parts:
        book = part.split('<tr class="book">', 1)[1].split("</tr>", 1)[0]
        engine = part.split('<tr class="engine">', 1)[1].split("</tr>", 1)[0]
        assert "<math" in book and "<math" in engine, part[:400]
    assert "book 2; engine 2" in " ".join(parts[2].split())


def test_identities_and_structured_answers_are_mathematics(report):
    """Chapter 10's identities for all tensors, and a steady motion's `at:`/`rates:`, are
    drawn as mathematics, not as code."""
    tensors = (report / "problems" / "symon-10-05.html").read_text(encoding="utf-8")
    identity = tensors.split('id="part-vectors-agree"', 1)[1].split("</section>", 1)[0]
    book = identity.split('<tr class="book">', 1)[1].split("</tr>", 1)[0]
    assert "<math" in book and "<code>" not in book
    steady = (report / "problems" / "symon-12-27.html").read_text(encoding="utf-8")
    part = steady.split('id="part-a"', 1)[1].split("</section>", 1)[0]
    book = part.split('<tr class="book">', 1)[1].split("</tr>", 1)[0]
    assert book.count("<math") == 2 and "<code>" not in book  # at: and rates:


def test_no_page_shows_an_exception(report):
    for path in pages(report):
        text = re.sub(r"<[^>]+>", " ", path.read_text(encoding="utf-8"))
        assert not EXCEPTION_TEXT.search(text), (path.name, EXCEPTION_TEXT.search(text))


def test_a_rerun_rebuilds_only_what_changed(tree, report):
    manifest = json.loads((report / ".pages.json").read_text("utf-8"))
    assert sorted(manifest["pages"]) == sorted(PROBLEMS)
    stamps = {p.name: p.stat().st_mtime_ns for p in (report / "problems").glob("*.html")}
    again = CliRunner().invoke(main, ["--root", str(tree), "report", "--serial", "--t-end",
                                      "5"])
    assert again.exit_code == 0 and f"all {len(PROBLEMS)} pages are up to date" in \
        again.output, again.output
    assert stamps == {p.name: p.stat().st_mtime_ns
                      for p in (report / "problems").glob("*.html")}
    key = tree / "answers" / "toy" / "3.2.yaml"
    text = key.read_text("utf-8")
    key.write_text(text + "\n# an edit\n", "utf-8")
    try:
        third = CliRunner().invoke(main, ["--root", str(tree), "report", "--serial",
                                          "--t-end", "5"])
    finally:
        key.write_text(text, "utf-8")
    assert third.exit_code == 0 and "[1/1] toy-3.2" in third.output, third.output
    changed = [p.name for p in (report / "problems").glob("*.html")
               if p.stat().st_mtime_ns != stamps[p.name]]
    assert changed == ["toy-3.2.html"]


@pytest.fixture(scope="module")
def browser():
    if not CHROMIUM.exists():
        pytest.skip(f"Chromium is not installed ({CHROMIUM} is absent): apt-get install -y "
                    "chromium chromium-driver (.ci/run does)")
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="Playwright is not installed (pip install -e '.[dev]')")
    with sync_api.sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
        context = pw.chromium.launch_persistent_context(
            profile, executable_path=str(CHROMIUM), headless=True, args=ARGS,
            viewport={"width": 1280, "height": 1000})
        try:
            yield context
        finally:
            context.close()


def open_page(browser, path: Path, query: str = ""):
    """The page at `path`, loaded, with everything that went wrong while loading."""
    page = browser.new_page()
    trouble: list[str] = []
    page.on("console", lambda m: trouble.append(f"console {m.type}: {m.text}")
            if m.type in ("error", "warning") else None)
    page.on("pageerror", lambda e: trouble.append(f"page error: {e}"))
    page.on("requestfailed", lambda r: trouble.append(f"request failed: {r.url}"))
    page.goto(path.as_uri() + query, wait_until="load")
    return page, trouble


# every element inside a table cell (or a .cell) must lie within it; a scroll box is a cell
# of its own only where it really scrolls something wider than a line of text; the page
# itself must not be wider than the window
OVERFLOW = """() => {
  const out = [];
  const doc = document.documentElement;
  if (doc.scrollWidth > window.innerWidth + 1)
    out.push(`the page is ${doc.scrollWidth}px wide in a ${window.innerWidth}px window`);
  for (const cell of document.querySelectorAll("td, th")) {
    const box = cell.getBoundingClientRect();
    for (const el of cell.querySelectorAll("*")) {
      const r = el.getBoundingClientRect();
      if (r.width === 0 && r.height === 0) continue;
      if (r.left < box.left - 1 || r.right > box.right + 1) {
        out.push(`${el.tagName} overflows its cell by ${Math.max(box.left - r.left,
                 r.right - box.right).toFixed(0)}px: ${cell.textContent.trim().slice(0, 60)}`);
        break;
      }
    }
  }
  for (const s of document.querySelectorAll(".cell")) {
    if (s.scrollWidth > s.clientWidth + 1)
      out.push(`a box scrolls (${s.scrollWidth}px in ${s.clientWidth}px): ` +
               s.textContent.trim().slice(0, 60));
  }
  return out;
}"""


def faults(page, trouble: list[str]) -> list[str]:
    """What is wrong with a loaded page: console errors and failed requests, equations
    with an empty box, images that did not load, elements overflowing their cells, and any
    exception's text."""
    boxes = page.eval_on_selector_all(
        "math", "els => els.map(e => { const r = e.getBoundingClientRect();"
                " return [r.width, r.height]; })")
    images = page.eval_on_selector_all(
        "img", "els => els.map(e => [e.getAttribute('src'), e.complete, e.naturalWidth])")
    out = list(trouble)
    out += [f"equation {i} has an empty box" for i, (w, h) in enumerate(boxes)
            if not (w > 0 and h > 0)]
    out += [f"image {src} did not load" for src, done, width in images
            if not (done and width > 0)]
    out += page.evaluate(OVERFLOW)
    found = EXCEPTION_TEXT.search(page.inner_text("body"))
    if found:
        out.append(f"exception text on the page: {found.group()}")
    return out


SHOWN = ("lim-2031", "lim-2035", "symon-09-01", "symon-12-27", "toy-3.2")  # kept as screenshots


@pytest.fixture(scope="module")
def screenshots(report, browser) -> list[Path]:
    """Screenshots of a few pages, kept for a reader under results/test-artifacts (taken
    here, not as a side effect of another test: under xdist the tests run in any order)."""
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    shots = []
    for path in pages(report):
        if path.stem in SHOWN:
            page, _ = open_page(browser, path)
            shots.append(ARTIFACTS / f"{path.stem}.png")
            page.screenshot(path=str(shots[-1]), full_page=True)
            page.close()
    return shots


def test_every_page_loads_cleanly_and_nothing_overflows(report, browser):
    for path in pages(report):
        page, trouble = open_page(browser, path)
        assert faults(page, trouble) == [], path.name
        if path.parent.name == "problems":
            assert page.locator("math").count() > 3, f"{path.name}: no equations"
        page.close()


def test_the_browser_checks_catch_a_broken_page(browser, tmp_path):
    """The checks above can fail: a script error, a missing image, an empty equation, an
    element wider than its cell and an exception's text are each reported."""
    bad = tmp_path / "bad.html"
    bad.write_text('<!DOCTYPE html><html><body><math display="block"></math>'
                   '<img src="missing.png"><script>console.error("boom")</script>'
                   '<table style="width:200px;table-layout:fixed"><tr><td>'
                   '<div style="width:600px">wide</div></td></tr></table>'
                   "<p>TypeError: Cannot convert expression to float</p>"
                   "</body></html>", encoding="utf-8")
    page, trouble = open_page(browser, bad)
    found = " | ".join(faults(page, trouble))
    page.close()
    for sign in ("boom", "missing.png", "empty box", "overflows its cell", "TypeError"):
        assert sign in found, found


def test_fractions_are_laid_out_as_mathematics(report, browser):
    """MathML that the browser did not lay out would flow as plain text, one line high: a
    fraction must stand taller than a letter."""
    page, _ = open_page(browser, report / "problems" / "lim-2031.html")
    letter = page.eval_on_selector("math mi", "e => e.getBoundingClientRect().height")
    fraction = page.eval_on_selector_all(
        "math mfrac", "els => Math.max(...els.map(e => e.getBoundingClientRect().height))")
    assert letter > 0 and fraction > 1.6 * letter, (letter, fraction)
    page.close()


def test_the_animation_runs(report, browser):
    page, trouble = open_page(browser, report / "problems" / "toy-3.2.html")
    label = page.locator("figure.animation .time").first
    first = label.inner_text()
    page.wait_for_timeout(600)
    assert label.inner_text() != first and first.startswith("t = "), first
    assert not trouble, trouble
    page.close()


def test_the_filters_select_by_book_and_outcome(report, browser):
    page, trouble = open_page(browser, report / "index.html")
    visible = "rows => rows.filter(r => !r.hidden).map(r => [r.dataset.book, r.dataset.status])"
    page.select_option("#filter-status", "erratum")
    shown = page.eval_on_selector_all("#outcomes tbody tr", visible)
    assert ["symon", "erratum"] in shown and all(s == "erratum" for _, s in shown)
    assert page.inner_text("#shown") == str(len(shown))
    page.select_option("#filter-status", "")
    page.select_option("#filter-book", "toy")
    shown = page.eval_on_selector_all("#outcomes tbody tr", visible)
    assert shown == [["toy", "pass"]] * 3
    page.select_option("#filter-book", "lim")
    page.select_option("#filter-status", "fail")
    assert page.eval_on_selector_all("#outcomes tbody tr", visible) == []
    assert not trouble, trouble
    page.close()
    page, trouble = open_page(browser, report / "index.html", "?book=toy&status=pass")
    shown = page.eval_on_selector_all("#outcomes tbody tr", visible)
    assert shown == [["toy", "pass"]] * 3 and not trouble
    page.close()


def test_screenshots_are_not_blank(screenshots):
    """The screenshots kept for a reader are images of the right size that are not blank
    (many distinct colours: text, equations, the status badges)."""
    from PIL import Image

    assert len(screenshots) == len(SHOWN)
    for shot in screenshots:
        image = Image.open(shot).convert("RGB")
        assert image.width == 1280 and image.height > 800
        colours = image.getcolors(maxcolors=1 << 20)
        assert colours is not None and len(colours) > 50
        dark = sum(n for n, (r, g, b) in colours if r + g + b < 200)
        assert dark > 2000  # text and equations, not an empty page


def test_every_page_of_a_full_report(browser):
    """The same checks on every page of a report built elsewhere (`make report`): set
    MECHBOOK_REPORT=results/report to run it; skipped otherwise (it takes minutes)."""
    import os

    where = os.environ.get("MECHBOOK_REPORT")
    if not where:
        pytest.skip("set MECHBOOK_REPORT to a report's directory to check all its pages")
    found = []
    for path in pages(Path(where)):
        page, trouble = open_page(browser, path)
        found += [f"{path.name}: {f}" for f in faults(page, trouble) + reading_faults(page, [])]
        page.close()
    assert found == [], "\n".join(found[:40])


# ---- what a reader trips on (issue 34) ------------------------------------------------------
READING = r"""() => {
  const out = [];
  const text = document.body.innerText;
  const py = text.match(/\b(True|False|None)\b/);
  if (py) out.push(`a Python value on the page: ${py[0]}`);
  for (const mo of document.querySelectorAll("math mo"))
    if (mo.textContent.trim() === "-") {
      out.push("a hyphen for a minus sign in a formula"); break;
    }
  for (const mn of document.querySelectorAll("math mn"))
    if (mn.textContent.trim().startsWith("-")) {
      out.push("a hyphen in a number: " + mn.textContent); break;
    }
  for (const t of document.querySelectorAll("svg.chart text"))
    if (/^-\d/.test(t.textContent.trim())) {
      out.push("a hyphen in a tick: " + t.textContent); break;
    }
  for (const row of document.querySelectorAll("math mtd > mrow")) {
    const kids = row.children;
    if (!kids.length) continue;
    if (kids[kids.length - 1].textContent.trim() === "(") out.push("a formula line ends in '('");
    if (kids[0].tagName.toLowerCase() === "mo" && kids[0].textContent.trim() === ")")
      out.push("a formula line starts with ')'");
  }
  for (const svg of document.querySelectorAll("svg.chart")) {
    const plot = svg.querySelector("rect.plot");
    if (!plot) { out.push("a chart without its plotting area"); continue; }
    const p = plot.getBBox();
    for (const g of svg.querySelectorAll(".legend")) {
      const b = g.getBBox();
      if (b.x < p.x + p.width && b.x + b.width > p.x &&
          b.y < p.y + p.height && b.y + b.height > p.y)
        out.push(`a legend on the curves: ${g.textContent}`);
    }
    if (!svg.querySelector(".legend") && svg.querySelectorAll("polyline, circle").length)
      out.push("a chart without a legend");
  }
  return out;
}"""


def reading_faults(page, roots: list[str]) -> list[str]:
    """What a reader trips on, in a loaded page (READING), and any of `roots` (absolute
    paths of the machine that built the report) in its text or markup."""
    out = page.evaluate(READING)
    html = page.content()
    out += [f"an absolute path: {r}" for r in roots if r in html]
    return out


def test_every_page_reads_well(report, tree, browser):
    roots = sorted({str(tree), str(tree.resolve()), str(tree.parent.resolve())})
    for path in pages(report):
        page, _ = open_page(browser, path)
        assert reading_faults(page, roots) == [], path.name
        page.close()


def test_the_reading_checks_catch_what_they_should(browser, tmp_path):
    bad = tmp_path / "bad.html"
    bad.write_text(
        '<!DOCTYPE html><html><body><p>stable True</p><p>/home/someone/tree/x.yaml</p>'
        '<math><mtable><mtr><mtd><mrow><mi>a</mi><mo>-</mo><mi>b</mi><mo>(</mo></mrow>'
        '</mtd></mtr><mtr><mtd><mrow><mo>)</mo><mn>-2</mn></mrow></mtd></mtr></mtable></math>'
        '<svg class="chart" width="300" height="200" xmlns="http://www.w3.org/2000/svg">'
        '<rect class="plot" x="40" y="20" width="200" height="150"/>'
        '<g class="legend"><text x="50" y="40">theta</text></g>'
        '<polyline points="40,20 240,170"/><text x="30" y="190">-0.1</text></svg>'
        "</body></html>", encoding="utf-8")
    page, _ = open_page(browser, bad)
    found = " | ".join(reading_faults(page, ["/home/someone/tree"]))
    page.close()
    for sign in ("Python value on the page: True", "hyphen for a minus", "hyphen in a number",
                 "hyphen in a tick", "ends in '('", "starts with ')'", "legend on the curves",
                 "absolute path"):
        assert sign in found, (sign, found)


def test_the_index_names_the_store_inside_the_tree(report, tree):
    index = (report / "index.html").read_text("utf-8")
    assert "<code>results/mechbook.h5</code>" in index
    assert str(tree) not in index and str(tree.resolve()) not in index


def test_shown_values_name_their_parameter_point(report, browser):
    """toy-3.2's frequencies at one point: the note says which (k and m, the defaults),
    with the values the Parameters table gives."""
    page, _ = open_page(browser, report / "problems" / "toy-3.2.html")
    notes = page.eval_on_selector_all(
        "section.part .note.point", "ns => ns.map(n => [n.innerText, "
        "[...n.querySelectorAll('math')].map(m => m.textContent.replace(/\\s/g, ''))])")
    table = dict(page.eval_on_selector_all(
        "#parameters + table tbody tr",
        "rows => rows.map(r => [r.cells[0].innerText.trim(), r.cells[1].innerText.trim()])"))
    page.close()
    assert notes and table, (notes, table)
    for text, pairs in notes:
        assert "(the default values)" in text and "book" in text and "engine" in text, text
        assert sorted(pairs) == sorted(f"{n}={v}" for n, v in table.items()), (pairs, table)


def test_the_animation_draws_rods_and_pivots(report, browser):
    """lim-2035's double pendulum: a rod from the pivot to the upper bob and one between
    the bobs, found in the motion (their lengths stay 3l and 4l while they turn); the
    canvas is dark along each rod at the frame drawn."""
    page, trouble = open_page(browser, report / "problems" / "lim-2035.html")
    page.click("figure.animation button")  # pause, then read the frame drawn
    page.wait_for_timeout(100)
    trouble = list(trouble)  # the page's own (the readback below warns of itself)
    samples = page.evaluate("""() => {
      const fig = document.querySelector("figure.animation");
      const data = JSON.parse(fig.querySelector("script.motion").textContent);
      const canvas = fig.querySelector("canvas"), ctx = canvas.getContext("2d");
      const frame = Number(fig.dataset.frame);
      const [x0, x1, y0, y1] = data.box;
      const scale = Math.min(canvas.width / (x1 - x0), canvas.height / (y1 - y0));
      const ox = (canvas.width - scale * (x1 - x0)) / 2;
      const oy = (canvas.height - scale * (y1 - y0)) / 2;
      const px = (p) => [ox + (p[0] - x0) * scale, canvas.height - oy - (p[1] - y0) * scale];
      const at = (e) => typeof e === "number" ? data.bodies[e].path[frame] : e;
      return data.links.map(([a, b]) => [0.35, 0.5, 0.65].map((f) => {
        const [ax, ay] = px(at(a)), [bx, by] = px(at(b));
        const x = Math.round(ax + f * (bx - ax)), y = Math.round(ay + f * (by - ay));
        const d = ctx.getImageData(x, y, 1, 1).data;
        return d[0] + d[1] + d[2];
      }));
    }""")
    motion = json.loads(page.locator("figure.animation script.motion").text_content())
    page.close()
    assert not trouble, trouble
    assert sorted(str(link) for link in motion["links"]) == ["[0, 1]", "[0, [0.0, 0.0]]"]
    assert [p["at"] for p in motion["pivots"]] == [[0.0, 0.0]]
    assert len(samples) == 2 and all(max(s) < 3 * 120 for s in samples), samples


@pytest.fixture(scope="module")
def unsimplified(tree, report) -> Path:
    """lim-2031's page with simplification off: every derived expression as derived."""
    out = tree / "results" / "report-unsimplified"
    built = CliRunner().invoke(main, ["--root", str(tree), "report", "lim-2031", "--serial",
                                      "--no-simulate", "--simplify-seconds", "0", "--out",
                                      str(out)])
    assert built.exit_code == 0, built.output
    return out / "problems" / "lim-2031.html"


def test_unsimplified_forms_say_so(unsimplified, report, browser):
    page, _ = open_page(browser, unsimplified)
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "lim-2031-unsimplified.png"), full_page=True)
    blocks = page.eval_on_selector_all(
        ".block", "bs => bs.map(b => [b.querySelector('h3').innerText, "
                  "!!b.querySelector('.unsimplified'), b.querySelector('.unsimplified') ? "
                  "b.querySelector('.unsimplified').getBoundingClientRect().height : 0])")
    page.close()
    said = {title: (note, height) for title, note, height in blocks}
    for title in ("Lagrangian L = T − V", "Kinetic energy T", "Equations of motion (Lagrange)"):
        assert said[title][0] and said[title][1] > 0, (title, said)
    text = unsimplified.read_text("utf-8")
    assert "not simplified: simplification is off (--simplify-seconds 0)" in text
    # with the defaults, toy-3.2's small expressions are simplified, and nothing says not
    toy = (report / "problems" / "toy-3.2.html").read_text("utf-8")
    assert 'class="note unsimplified"' not in toy
