"""The documentation site opened in a real browser (issue 34, item 2).

The built HTML (``$HAMILTON_ORBITS_DOCS_HTML``, else ``docs/_build/html``, built
once by :func:`site` when missing) is served on localhost and opened in Debian's
headless Chromium through Playwright: the front page, the API pages of
``Simulation`` and ``integrate``, a gallery page, a page with a
``Trajectory.plot3d`` figure, and the search page with the query ``KeplerOrbit``.
A page fails (:func:`check_page`) on any HTTP response >= 400 or failed request
for it or its resources, any request that leaves localhost (nothing may download
when the site is viewed), any image that did not load, and any JavaScript error
(an uncaught exception or a console message of type error).  A screenshot of
every page goes to ``$HAMILTON_ORBITS_ARTIFACTS``, else
``test-artifacts/browser/`` at the repository root.

The checks themselves are tested on tiny pages written here (a broken image, a
thrown error, ...), so that a check that stopped catching anything fails.

Chromium is the system's (``apt-get install chromium``), never a browser that
Playwright downloads; Playwright for Python is in the ``test`` extra.  Without
either, the tests skip and say how to install them.
"""

from __future__ import annotations

import contextlib
import functools
import http.server
import os
import re
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any
from urllib.parse import urljoin, urlsplit

import pytest

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]
TIMEOUT_MS = 60_000  # a loaded 2-core machine is slow to render plotly's WebGL

# A 1x1 PNG (red), for the pages of the checks' own tests.
PNG_1X1 = bytes.fromhex(
    "89504e470d0a1a0a0000000d4948445200000001000000010802000000907753de"
    "0000000c4944415408d763f8cfc000000301010018dd8db00000000049454e44ae426082")


# --- the checks --------------------------------------------------------------------------

def _image_problems(page: Any) -> list[str]:
    """Images that did not load: ``decode()`` rejects, or no natural width (an SVG
    without an intrinsic size may have none; its response is checked instead)."""
    broken = page.evaluate("""async () => {
        const bad = [];
        for (const img of Array.from(document.images)) {
            img.loading = "eager";  // lazy images below the fold load too
            let decoded = true;
            try { await img.decode(); } catch (e) { decoded = false; }
            const svg = /\\.svg([?#]|$)/i.test(img.currentSrc || img.src);
            if (!decoded || (img.naturalWidth === 0 && !svg)) bad.push(img.currentSrc || img.src);
        }
        return bad;
    }""")
    return [f"image not loaded: {src}" for src in broken]


def check_page(browser: Any, url: str, screenshot: Path | None = None,
               ready: Callable[[Any], None] | None = None) -> list[str]:
    """Open ``url`` in a fresh context of ``browser``; the problems found (empty: none).

    ``ready(page)`` runs after the page's load event (to wait for what a script
    draws, or a search's results); the problems are collected until it returns and
    the images have decoded.  A screenshot of the whole page goes to ``screenshot``.
    """
    problems: list[str] = []
    local = urlsplit(url).netloc
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    page = context.new_page()

    def route(r: Any) -> None:  # nothing may come from elsewhere than the site
        parts = urlsplit(r.request.url)
        if parts.scheme in ("data", "blob") or parts.netloc == local:
            r.continue_()
        else:
            problems.append(f"request off the site: {r.request.url}")
            r.abort()

    page.route("**/*", route)
    page.on("response", lambda resp: resp.status >= 400 and problems.append(
        f"HTTP {resp.status}: {resp.url}"))
    page.on("requestfailed", lambda req: problems.append(
        f"request failed ({req.failure}): {req.url}"))
    page.on("pageerror", lambda err: problems.append(f"JavaScript error: {err}"))
    page.on("console", lambda msg: msg.type == "error" and problems.append(
        f"console error: {msg.text}"))
    try:
        page.goto(url, wait_until="load", timeout=TIMEOUT_MS)
        if ready is not None:
            ready(page)
        problems.extend(_image_problems(page))
        page.wait_for_load_state("networkidle", timeout=TIMEOUT_MS)
        if screenshot is not None:
            screenshot.parent.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=str(screenshot), full_page=True)
    except Exception as err:  # a timeout waiting for `ready` is a problem of the page
        problems.append(f"{type(err).__name__}: {str(err).splitlines()[0]}")
    finally:
        context.close()
    return problems


def assert_page_ok(browser: Any, url: str, screenshot: Path | None = None,
                   ready: Callable[[Any], None] | None = None) -> None:
    problems = check_page(browser, url, screenshot, ready)
    assert not problems, f"{url}:\n  " + "\n  ".join(problems)


# --- serving and the browser -----------------------------------------------------------

class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        pass


@contextlib.contextmanager
def serve(directory: Path) -> Iterator[str]:
    """Serve ``directory`` on localhost (an ephemeral port) in a thread; the base URL."""
    handler = functools.partial(_QuietHandler, directory=str(directory))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()
        thread.join()


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    """Debian's headless Chromium, driven by Playwright (skips without them)."""
    if not CHROMIUM.exists():
        pytest.skip(f"no Chromium at {CHROMIUM}: install Debian's package "
                    "(sudo apt-get install -y chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("Playwright for Python is missing: pip install -e '.[test]' "
                    "(it drives the system's Chromium; no browser download is needed)")
    with sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


@pytest.fixture(scope="session")
def artifacts() -> Path:
    """Where the screenshots go: ``$HAMILTON_ORBITS_ARTIFACTS`` or test-artifacts/browser."""
    path = Path(os.environ.get("HAMILTON_ORBITS_ARTIFACTS") or ROOT / "test-artifacts" / "browser")
    path.mkdir(parents=True, exist_ok=True)
    return path


# --- the checks' own tests, on tiny pages --------------------------------------------

@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    root = tmp_path_factory.mktemp("tiny-pages")
    (root / "dot.png").write_bytes(PNG_1X1)
    (root / "not-an-image.png").write_text("this is text, served as image/png")
    (root / "style.css").write_text("body { font-family: sans-serif; }")
    pages = {
        "good.html": '<link rel="stylesheet" href="style.css"><img src="dot.png" alt="dot">'
                     '<script>console.log("fine")</script>',
        "missing-image.html": '<img src="nowhere.png" alt="gone">',
        "undecodable-image.html": '<img src="not-an-image.png" alt="text">',
        "thrown-error.html": '<script>throw new Error("boom from the page")</script>',
        "console-error.html": '<script>console.error("something went wrong")</script>',
        "missing-script.html": '<script src="_static/missing.js"></script>',
        "offsite.html": '<script src="https://cdn.example.invalid/plotly.min.js"></script>',
    }
    for name, body in pages.items():
        (root / name).write_text(f"<!doctype html><html><head><meta charset='utf-8'>"
                                 f"<title>{name}</title></head><body>{body}</body></html>")
    with serve(root) as base:
        yield base


def test_a_good_page_passes(browser, tiny, artifacts):
    shot = artifacts / "check-good.png"
    assert check_page(browser, tiny + "good.html", shot) == []
    assert shot.stat().st_size > 0


@pytest.mark.parametrize(("page", "expected"), [
    ("missing-image.html", [r"HTTP 404: .*/nowhere\.png", r"image not loaded: .*/nowhere\.png"]),
    ("undecodable-image.html", [r"image not loaded: .*/not-an-image\.png"]),
    ("thrown-error.html", [r"JavaScript error: .*boom from the page"]),
    ("console-error.html", [r"console error: something went wrong"]),
    ("missing-script.html", [r"HTTP 404: .*/_static/missing\.js"]),
    ("offsite.html", [r"request off the site: https://cdn\.example\.invalid/plotly\.min\.js"]),
])
def test_a_broken_page_fails(browser, tiny, page, expected):
    problems = check_page(browser, tiny + page)
    for pattern in expected:
        assert any(re.search(pattern, p) for p in problems), (pattern, problems)


def test_assert_page_ok_names_the_page_and_its_problems(browser, tiny):
    with pytest.raises(AssertionError, match=r"thrown-error\.html:\n.*boom from the page"):
        assert_page_ok(browser, tiny + "thrown-error.html")


def test_waiting_for_what_never_comes_fails(browser, tiny):
    def never(page):
        page.wait_for_selector("#not-there", timeout=1000)

    (problem,) = check_page(browser, tiny + "good.html", ready=never)
    assert problem.startswith("TimeoutError")


# --- the site ---------------------------------------------------------------------------

def build_site(source: Path, out: Path) -> float:
    """Build the HTML site of ``source`` into ``out``; the seconds it took."""
    start = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", str(source), str(out)],
                         cwd=ROOT, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if res.returncode != 0 or not (out / "index.html").exists():
        pytest.fail(f"sphinx could not build {source} ({seconds:.0f} s):\n"
                    + (res.stdout + res.stderr)[-4000:])
    return seconds


@pytest.fixture(scope="session")
def site(request: pytest.FixtureRequest, artifacts: Path) -> Path:
    """The built site: ``$HAMILTON_ORBITS_DOCS_HTML``, else docs/_build/html (built
    here, once, when it has no index.html)."""
    given = os.environ.get("HAMILTON_ORBITS_DOCS_HTML")
    html = Path(given) if given else ROOT / "docs" / "_build" / "html"
    if (html / "index.html").exists():
        return html
    if given:
        pytest.fail(f"HAMILTON_ORBITS_DOCS_HTML={given} has no index.html: build the site "
                    "first (python -m sphinx -b html docs docs/_build/html)")
    if not (ROOT / "docs" / "conf.py").exists():
        pytest.skip("no docs/conf.py in this tree: no site to build")
    seconds = build_site(ROOT / "docs", html)
    line = f"test_docs_browser: built the site into {html} in {seconds:.0f} s"
    (artifacts / "build-time.txt").write_text(line + "\n")
    reporter = request.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        reporter.write_line(line)
    return html


@pytest.fixture(scope="session")
def site_url(site: Path, browser: Any) -> Iterator[str]:
    with serve(site) as base:
        yield base


def _links(page: Path) -> list[str]:
    return re.findall(r'href="([^"]+)"', page.read_text(errors="replace"))


def api_page(site: Path, name: str) -> str:
    """The site-relative address of ``name``'s API page: the autosummary page
    ``api/generated/<name>.html``, else where a link of api/index.html leads for it
    (a page named after it, or an anchor ``#<name>`` on a page of several names)."""
    generated = f"api/generated/{name}.html"
    if (site / generated).exists():
        return generated
    index = site / "api" / "index.html"
    if index.exists():
        short = name.rsplit(".", 1)[-1]
        for href in _links(index):
            parts = urlsplit(href)
            if parts.scheme or parts.netloc:
                continue
            stem = Path(parts.path).stem
            if parts.fragment == name or stem == name or stem.endswith("." + short):
                target = (index.parent / parts.path).resolve() if parts.path else index
                if target.is_file():
                    where = target.relative_to(site.resolve()).as_posix()
                    return f"{where}#{parts.fragment}" if parts.fragment == name else where
    pytest.fail(f"no API page of {name}: neither {generated} nor a link to it in api/index.html")


def test_api_pages_are_found_by_either_convention(tmp_path):
    site = tmp_path / "html"
    (site / "api" / "generated").mkdir(parents=True)
    (site / "api" / "generated" / "hamilton_orbits.Simulation.html").write_text("<p>S</p>")
    (site / "api" / "index.html").write_text(
        '<a href="https://example.org/hamilton_orbits.integrate.html">elsewhere</a>'
        '<a href="flows.html#hamilton_orbits.integrate">integrate</a>'
        '<a href="#hamilton_orbits.KeplerOrbit">KeplerOrbit</a>'
        '<a href="gone.html#hamilton_orbits.Archive">a page that is not there</a>')
    (site / "api" / "flows.html").write_text("<p>I</p>")
    assert api_page(site, "hamilton_orbits.Simulation") == \
        "api/generated/hamilton_orbits.Simulation.html"
    assert api_page(site, "hamilton_orbits.integrate") == \
        "api/flows.html#hamilton_orbits.integrate"
    assert api_page(site, "hamilton_orbits.KeplerOrbit") == \
        "api/index.html#hamilton_orbits.KeplerOrbit"
    for name in ("hamilton_orbits.Archive", "hamilton_orbits.System"):
        with pytest.raises(pytest.fail.Exception, match=f"no API page of {name}"):
            api_page(site, name)


def gallery_page(site: Path) -> str:
    """An example's page of the sphinx-gallery (one that shows a figure)."""
    gallery = site / "gallery"
    pages = sorted(p for p in gallery.rglob("*.html") if p.name != "index.html"
                   and "sphx-glr" in p.read_text(errors="replace")) if gallery.is_dir() else []
    if not pages:
        pytest.fail(f"no gallery example page under {gallery}")
    return pages[0].relative_to(site).as_posix()


def _plotly_ready(page: Any) -> None:
    """Wait until plotly has drawn a 3-D scene with its time slider."""
    page.wait_for_selector(".js-plotly-plot .gl-container canvas", state="attached",
                           timeout=TIMEOUT_MS)
    page.wait_for_selector(".js-plotly-plot .slider-container", state="attached",
                           timeout=TIMEOUT_MS)


def test_front_page(browser, site_url, artifacts):
    assert_page_ok(browser, site_url, artifacts / "front-page.png")


@pytest.mark.parametrize("name", ["hamilton_orbits.Simulation", "hamilton_orbits.integrate"])
def test_api_page(browser, site, site_url, artifacts, name):
    url = urljoin(site_url, api_page(site, name))

    def documented(page):  # the page documents the name itself (an anchor with its id)
        page.wait_for_selector(f'[id="{name}"]', state="attached", timeout=TIMEOUT_MS)

    assert_page_ok(browser, url, artifacts / f"api-{name}.png", documented)


def test_gallery_page(browser, site, site_url, artifacts):
    url = urljoin(site_url, gallery_page(site))
    assert_page_ok(browser, url, artifacts / "gallery-example.png")


def test_plot3d_page(browser, site, site_url, artifacts, tmp_path):
    """A page of the site that holds a plotly figure; else one written here with
    ``Trajectory.plot3d`` (as the gallery would, plotly.js embedded)."""
    pages = sorted(p for p in site.rglob("*.html")
                   if "js-plotly-plot" in (text := p.read_text(errors="replace"))
                   or "Plotly.newPlot" in text)
    if pages:
        assert_page_ok(browser, urljoin(site_url, pages[0].relative_to(site).as_posix()),
                       artifacts / "plot3d.png", _plotly_ready)
        return
    pytest.importorskip("plotly", reason="plotly is in the test extra: pip install -e '.[test]'")
    import numpy as np

    from hamilton_orbits import Body, System, integrate

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0]),
                Body("comet", 0.0, [0.0, 3.0, 0.5], [-0.45, 0, 0.1])])
    fig = integrate(s, np.linspace(0, 4 * np.pi, 400)).plot3d()
    fig.write_html(tmp_path / "plot3d.html", include_plotlyjs=True, auto_play=False)
    with serve(tmp_path) as base:
        assert_page_ok(browser, base + "plot3d.html", artifacts / "plot3d.png", _plotly_ready)


def test_search_finds_kepler_orbit(browser, site, site_url, artifacts):
    """Sphinx's search (searchindex.js, run in the page) lists KeplerOrbit's API page."""
    path, _, anchor = api_page(site, "hamilton_orbits.KeplerOrbit").partition("#")
    found: list[str] = []

    def results(page):
        page.wait_for_function(
            """([path, anchor]) => Array.from(document.querySelectorAll('#search-results a'))
                   .some(a => { const u = new URL(a.href);
                                return u.pathname === '/' + path
                                       && (!anchor || u.hash === '#' + anchor); })""",
            arg=[path, anchor], timeout=TIMEOUT_MS)
        found.extend(page.eval_on_selector_all("#search-results a", "as => as.map(a => a.href)"))

    assert_page_ok(browser, urljoin(site_url, "search.html?q=KeplerOrbit"),
                   artifacts / "search-KeplerOrbit.png", results)
    link = next(h for h in found if urlsplit(h).path == "/" + path)
    assert_page_ok(browser, link, artifacts / "search-result-KeplerOrbit.png")
