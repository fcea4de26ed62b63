"""`mechbook report` in a real browser: Debian's headless Chromium, driven by Playwright
(never allowed to fetch a browser of its own). Every page loads without console errors or
failed requests, every equation is laid out as mathematics (non-empty boxes, fractions
taller than a letter), every image loads, the index's filters work; and a screenshot is
taken and checked not to be blank.

The report is built once, for a scratch tree holding lim-2031 (every part passes),
symon-09-01 (two errata) and toy-3.2 (a third book declared only in data). Without
Chromium the browser tests are skipped, saying why; the rest still run.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_books import third_book_tree

from mechbook.app.cli import main

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = Path("/usr/bin/chromium")
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
PROBLEMS = ("lim-2031", "symon-09-01", "toy-3.2")


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    tree = third_book_tree(tmp_path_factory.mktemp("tree"))
    for sub in ("lim/2031", "symon/09-01"):
        for kind in ("problems", "answers"):
            dest = tree / kind / f"{sub}.yaml"
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / kind / f"{sub}.yaml", dest)
    runner = CliRunner()
    checked = runner.invoke(main, ["--root", str(tree), "check", *PROBLEMS, "--serial"])
    assert checked.exit_code == 0, checked.output
    built = runner.invoke(main, ["--root", str(tree), "report", "--serial", "--t-end", "5"])
    assert built.exit_code == 0, built.output
    out = tree / "results" / "report"
    assert f"report written to {out / 'index.html'}" in built.output
    return out


def pages(report: Path) -> list[Path]:
    return [report / "index.html", *sorted((report / "problems").glob("*.html"))]


def test_the_report_holds_every_problem_part_and_outcome(report):
    index = (report / "index.html").read_text(encoding="utf-8")
    assert [p.stem for p in sorted((report / "problems").glob("*.html"))] == sorted(PROBLEMS)
    for pid in PROBLEMS:
        assert f'href="problems/{pid}.html"' in index
    assert index.count('data-status="erratum"') == 2  # symon-09-01 e-Qu, e-Qw
    assert index.count('data-status="pass"') == 6 + 3 + 3
    assert 'data-book="toy"' in index and "A Toy Book of Oscillators" in index
    errata = index.split('id="errata"', 1)[1].split('id="unsupported"', 1)[0]
    assert "e-Qu" in errata and "e-Qw" in errata
    page = (report / "problems" / "symon-09-01.html").read_text(encoding="utf-8")
    assert page.count('corrected value:</p><math') == 2 and "the erratum's derivation" in page
    toy = (report / "problems" / "toy-3.2.html").read_text(encoding="utf-8")
    assert toy.count("<math") >= 6 and "simulation-main.png" in toy
    assert "modes-main-1.png" in toy
    for page in pages(report):  # offline: nothing is fetched from elsewhere
        text = page.read_text(encoding="utf-8")
        assert "http://" not in text.replace("http://www.w3.org/1998/Math/MathML", "")
        assert "https://" not in text


def test_the_book_and_the_engine_side_by_side(report):
    """Each part of the toy problem shows the book's value and the engine's, derived
    independently (the engine's frequency is its own sqrt(k/m), at one point both 2)."""
    toy = (report / "problems" / "toy-3.2.html").read_text(encoding="utf-8")
    rows = toy.split('<tr id="part-')[1:]
    assert [r.split('"', 1)[0] for r in rows] == ["a", "b", "c"]
    for row in rows:
        cells = row.split("<td")
        assert "<math" in cells[3] and "<math" in cells[4], row[:300]
    assert "book 2; engine 2" in " ".join(rows[2].split())


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


def faults(page, trouble: list[str]) -> list[str]:
    """What is wrong with a loaded page: console errors and failed requests, equations
    with an empty box, images that did not load."""
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
    return out


def test_every_page_loads_cleanly_with_equations_and_images(report, browser):
    for path in pages(report):
        page, trouble = open_page(browser, path)
        assert faults(page, trouble) == [], path.name
        if path.parent.name == "problems":
            assert page.locator("math").count() > 5, f"{path.name}: no equations"
        if path.stem in ("lim-2031", "toy-3.2"):  # modes, simulation, cross-check figures
            assert page.locator("img").count() >= 2, f"{path.name}: no figures"
        page.close()


def test_the_browser_checks_catch_a_broken_page(browser, tmp_path):
    """The checks above can fail: a script error, a missing image and an empty equation are
    each reported."""
    bad = tmp_path / "bad.html"
    bad.write_text('<!DOCTYPE html><html><body><math display="block"></math>'
                   '<img src="missing.png"><script>console.error("boom")</script>'
                   "</body></html>", encoding="utf-8")
    page, trouble = open_page(browser, bad)
    found = " | ".join(faults(page, trouble))
    page.close()
    assert "boom" in found and "missing.png" in found and "empty box" in found, found


def test_fractions_are_laid_out_as_mathematics(report, browser):
    """MathML that the browser did not lay out would flow as plain text, one line high: a
    fraction must stand taller than a letter."""
    page, _ = open_page(browser, report / "problems" / "lim-2031.html")
    letter = page.eval_on_selector("math mi", "e => e.getBoundingClientRect().height")
    fraction = page.eval_on_selector_all(
        "math mfrac", "els => Math.max(...els.map(e => e.getBoundingClientRect().height))")
    assert letter > 0 and fraction > 1.6 * letter, (letter, fraction)
    page.close()


def test_the_filters_select_by_book_and_outcome(report, browser):
    page, trouble = open_page(browser, report / "index.html")
    visible = "rows => rows.filter(r => !r.hidden).map(r => [r.dataset.book, r.dataset.status])"
    page.select_option("#filter-status", "erratum")
    shown = page.eval_on_selector_all("#outcomes tbody tr", visible)
    assert shown == [["symon", "erratum"], ["symon", "erratum"]]
    assert page.inner_text("#shown") == "2"
    page.select_option("#filter-status", "")
    page.select_option("#filter-book", "toy")
    shown = page.eval_on_selector_all("#outcomes tbody tr", visible)
    assert shown == [["toy", "pass"]] * 3
    page.select_option("#filter-book", "lim")
    page.select_option("#filter-status", "fail")
    assert page.eval_on_selector_all("#outcomes tbody tr", visible) == []
    assert not trouble, trouble
    page.close()
    page, trouble = open_page(browser, report / "index.html", "?book=symon&status=pass")
    shown = page.eval_on_selector_all("#outcomes tbody tr", visible)
    assert shown == [["symon", "pass"]] * 3 and not trouble
    page.close()


def test_screenshot(report, browser, tmp_path):
    """A screenshot of a problem page: an image of the right size that is not blank (many
    distinct colours: text, equations, the status badges)."""
    from PIL import Image

    page, trouble = open_page(browser, report / "problems" / "lim-2031.html")
    shot = tmp_path / "lim-2031.png"
    page.screenshot(path=str(shot), full_page=True)
    page.close()
    assert not trouble
    image = Image.open(shot).convert("RGB")
    assert image.width == 1280 and image.height > 1000
    colours = image.getcolors(maxcolors=1 << 20)
    assert colours is not None and len(colours) > 50
    dark = sum(n for n, (r, g, b) in colours if r + g + b < 200)
    assert dark > 2000  # text and equations, not an empty page
