"""The course site (issue 24): built once per run, checked as files, then page by page in headless Chromium.

The build (``tools/build_site.py``, what ``make docs`` runs) goes into a temporary folder: Sphinx with warnings
as errors, nitpicky for slamlab's own references, the notebooks' stored outputs (never executed). Checked here:
no warning in the build's output; every public function, class and method (the walker of the docstring test)
has an entry in the API reference; every chapter and lab is in the table of contents; the cross-references go
both ways. Then, in Chromium, from a local ``http.server`` on 127.0.0.1: every page loads with no console
error, no failed request and no request leaving the site, every image loaded; equations typeset by the local
MathJax; a search for "Kalman" finds chapter 01. Screenshots of a chapter, a lab and an API page go to
``build/site-screenshots/`` (CI artefacts). One file, so that ``--dist loadfile`` builds the site once.

The build time and the browser checks' time are printed (``-s`` shows them) and written beside the screenshots.
"""

from __future__ import annotations

import functools
import http.server
import importlib
import importlib.util
import json
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path
from urllib.parse import urlsplit

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
_spec = importlib.util.spec_from_file_location("_browser_suite_site", Path(__file__).with_name(
    "test_notebooks_in_browser.py"))
suite = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(suite)
browser = suite.browser  # Chromium via Playwright; skips (or fails under SLAMLAB_REQUIRE_BROWSER=1) without it

CHAPTERS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
LABS = sorted((ROOT / "notebooks" / "labs").glob("*_lab.ipynb"))
SHOTS = ROOT / "build" / "site-screenshots"
TIMES: dict[str, float] = {}


def public_callables():
    """Every public function, class and method of slamlab, exactly as the docstring test walks them
    (``public_callables`` of tests/test_docstrings.py, issue 23: classmethods and staticmethods included)."""
    spec = importlib.util.spec_from_file_location("_docstring_walker", ROOT / "tests" / "test_docstrings.py")
    walker = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(walker)
    return walker.public_callables()


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """Build the site once; yield (folder, the build's output). ``SLAMLAB_SITE_DIR`` names a site already built
    (``make docs``) to check instead, with no build log (for working on the checks themselves)."""
    prebuilt = os.environ.get("SLAMLAB_SITE_DIR")
    if prebuilt:
        return Path(prebuilt).resolve(), ""
    work = tmp_path_factory.mktemp("site-work")
    out = work / "html"
    start = time.perf_counter()
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "build_site.py"), "--out", str(out),
                           "--work", str(work)], cwd=ROOT, capture_output=True, text=True, check=False)
    TIMES["build_s"] = time.perf_counter() - start
    log = done.stdout + done.stderr
    assert done.returncode == 0, f"the site build failed:\n{log[-6000:]}"
    TIMES["pages"] = sum(1 for p in out.rglob("*.html") if "_static" not in p.parts)
    print(f"\nsite build: {TIMES['build_s']:.0f} s, {TIMES['pages']} pages")
    return out, log


def test_build_has_no_warnings(site):
    _, log = site
    problems = [line for line in log.splitlines()
                if re.search(r"WARNING|ERROR|Warning:|SEVERE", line)]
    assert not problems, "the site build warned:\n" + "\n".join(problems[:40])


def _ids(html: str) -> set[str]:
    return set(re.findall(r'<dt class="sig sig-object py[^"]*" id="([^"]+)"', html))


def test_every_public_callable_is_in_the_api_reference(site):
    out, _ = site
    documented = set()
    for page in (out / "api").glob("*.html"):
        documented |= _ids(page.read_text(encoding="utf-8"))
    missing = sorted(name for name, _ in public_callables() if name not in documented)
    assert not missing, f"{len(missing)} public callables have no API entry: {', '.join(missing[:30])}"


def test_every_chapter_and_lab_is_in_the_table_of_contents(site):
    out, _ = site
    toc = {}
    for index in ("chapters/index.html", "labs/index.html"):
        html = (out / index).read_text(encoding="utf-8")
        wrapper = html[html.index('class="toctree-wrapper'):]
        toc[index] = set(re.findall(r'href="([^"#]+)\.html"', wrapper))
    missing = [p.stem for p in CHAPTERS if p.stem not in toc["chapters/index.html"]]
    missing += [p.stem for p in LABS if p.stem not in toc["labs/index.html"]]
    assert not missing, f"not in the table of contents: {missing}"
    for p in CHAPTERS:
        assert (out / "chapters" / f"{p.stem}.html").is_file()
    for p in LABS:
        assert (out / "labs" / f"{p.stem}.html").is_file()
    root = (out / "index.html").read_text(encoding="utf-8")
    for section in ("chapters/index.html", "labs/index.html", "api/index.html", "labs/instructor.html"):
        assert section in root or section == "labs/instructor.html", f"{section} not linked from the root"


def test_cross_references_go_both_ways(site):
    """Chapter 01 links kf_predict to its API entry; that entry links back to chapter 01."""
    out, _ = site
    chapter = (out / "chapters" / "01_kalman_filters.html").read_text(encoding="utf-8")
    assert "../api/filters.html#slamlab.filters.kalman.kf_predict" in chapter  # the chapter's box
    assert re.search(r'<a class="slamlab-code-ref" href="../api/filters.html#slamlab.filters.kalman.kf_predict"[^>]*>'
                     r'<span class="n">sl</span>', chapter), "sl.filters.kf_predict in a code cell is not linked"
    api = (out / "api" / "filters.html").read_text(encoding="utf-8")
    entry = api[api.index('id="slamlab.filters.kalman.kf_predict"'):]
    entry = entry[:entry.index('<dt class="sig sig-object py')]  # up to the next entry
    assert "../chapters/01_kalman_filters.html" in entry
    lab = (out / "labs" / "01_kalman_filters_lab.html").read_text(encoding="utf-8")
    assert "YOUR CODE HERE" in lab, "the lab page is not the student version"
    assert "BEGIN SOLUTION" not in lab, "the lab page shows the solutions"
    guide = (out / "labs" / "instructor.html").read_text(encoding="utf-8")
    assert "autograde" in guide
    assert "minutes" in guide


# ---------------------------------------------------------------- in the browser
class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def server(site):
    """The built site over http on 127.0.0.1 (a free port); yields its base URL."""
    out, _ = site
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(out)))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}"
    finally:
        httpd.shutdown()
        httpd.server_close()


_IMAGES = """async () => {
    const imgs = [...document.images];
    for (const img of imgs) { img.loading = 'eager'; }
    await Promise.all(imgs.map(img => img.complete ? null : new Promise(r => {
        img.addEventListener('load', r); img.addEventListener('error', r); })));
    return imgs.filter(img => img.naturalWidth === 0).map(img => img.currentSrc || img.src);
}"""
_MATH = """async () => {
    const loaded = !!(window.MathJax && MathJax.startup);
    if (loaded) await MathJax.startup.promise;
    // TeX left as text in the prose (math the Markdown parser did not see as math)
    const walker = document.createTreeWalker(document.querySelector('main') || document.body, NodeFilter.SHOW_TEXT);
    const raw = [];
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
        if (n.parentElement.closest('pre, code, script, style, mjx-container, .highlight, .output')) continue;
        if (/\\$\\$|\\\\(mathbf|frac|hat|tilde|sigma|alpha|theta|qquad)\\b/.test(n.textContent)) raw.push(n.textContent.slice(0, 80));
    }
    return {loaded: loaded, raw: raw.slice(0, 3),
            typeset: document.querySelectorAll('mjx-container').length,
            errors: document.querySelectorAll('mjx-merror').length,
            pending: document.querySelectorAll('.math:not(:has(mjx-container))').length};
}"""


def _aborted_icon(request) -> bool:
    """The favicon's request cut off by the next navigation (the browser fetches it lazily, after load)."""
    return request.url.endswith("/_static/favicon.svg") and "ERR_ABORTED" in (request.failure or "")


def _open(page, url: str, base: str) -> list[str]:
    """Open ``url``; return what went wrong: console errors, failed requests, requests leaving the site."""
    problems: list[str] = []
    on_console = lambda m: problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None
    on_failed = lambda r: None if _aborted_icon(r) else problems.append(f"failed request: {r.url} ({r.failure})")
    on_request = lambda r: (problems.append(f"request leaving the site: {r.url}")
                            if not (r.url.startswith(base) or urlsplit(r.url).scheme in ("data", "blob")) else None)
    on_response = lambda r: problems.append(f"HTTP {r.status}: {r.url}") if r.status >= 400 else None
    page.on("console", on_console)
    page.on("requestfailed", on_failed)
    page.on("request", on_request)
    page.on("response", on_response)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    try:
        page.goto(url, wait_until="load", timeout=60_000)
        broken = page.evaluate(_IMAGES)
        problems += [f"image not loaded: {src}" for src in broken]
        math = page.evaluate(_MATH)
        if math["raw"] or (math["loaded"] and (math["errors"] or math["pending"])):
            problems.append(f"equations: {math}")
        # MathJax asks for its fonts after typesetting: let them arrive (or fail, and be counted) before the next
        # page's navigation cuts them off (seen once: MathJax_Main-Bold.woff ERR_ABORTED on chapter 02)
        page.wait_for_load_state("networkidle", timeout=30_000)
    finally:
        page.remove_listener("console", on_console)
        page.remove_listener("requestfailed", on_failed)
        page.remove_listener("request", on_request)
        page.remove_listener("response", on_response)
    return problems


@pytest.mark.browser
def test_every_page_in_the_browser(site, server, browser):
    """Every page: no console error, no failed request, nothing fetched from outside, every image loaded;
    equations typeset on the pages that have them. Screenshots of a chapter, a lab and an API page."""
    out, _ = site
    start = time.perf_counter()
    pages = sorted(p.relative_to(out).as_posix() for p in out.rglob("*.html") if "_static" not in p.parts)
    context = browser.new_context(viewport={"width": 1280, "height": 900}, service_workers="block")
    page = context.new_page()
    problems = {}
    try:
        for rel in pages:
            found = _open(page, f"{server}/{rel}", server)
            if found:
                problems[rel] = found
        # equations: chapter 01 has many, typeset by the local MathJax
        _open(page, f"{server}/chapters/01_kalman_filters.html", server)
        math = page.evaluate(_MATH)
        assert math["loaded"], "MathJax did not load on chapter 01"
        assert math["typeset"] > 20, f"chapter 01's equations were not typeset: {math}"
        assert not math["errors"], f"chapter 01's equations: {math}"
        SHOTS.mkdir(parents=True, exist_ok=True)
        for name, rel in (("chapter", "chapters/01_kalman_filters.html"), ("lab", "labs/01_kalman_filters_lab.html"),
                          ("api", "api/filters.html")):
            _open(page, f"{server}/{rel}", server)
            page.screenshot(path=str(SHOTS / f"{name}.png"))
    finally:
        context.close()
    TIMES["browser_pages_s"] = time.perf_counter() - start
    TIMES["browser_pages"] = len(pages)
    assert not problems, "\n".join(f"{rel}: {'; '.join(p[:5])}" for rel, p in problems.items())


@pytest.mark.browser
def test_search_finds_chapter_01(site, server, browser):
    start = time.perf_counter()
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    page = context.new_page()
    try:
        problems = _open(page, f"{server}/search.html?q=Kalman", server)
        page.wait_for_function("() => document.querySelectorAll('#search-results ul.search li').length > 0"
                               " || /did not match|no documents/i.test(document.body.innerText)",
                               timeout=60_000)
        hrefs = page.evaluate("() => [...document.querySelectorAll('#search-results ul.search li a')]"
                              ".map(a => a.getAttribute('href'))")
        page.screenshot(path=str(SHOTS / "search.png")) if SHOTS.is_dir() else None
    finally:
        context.close()
    TIMES["search_s"] = time.perf_counter() - start
    SHOTS.mkdir(parents=True, exist_ok=True)
    (SHOTS / "times.json").write_text(json.dumps(TIMES, indent=1))
    print(f"\nsite times: {TIMES}")
    assert not problems, problems
    assert any("chapters/01_kalman_filters" in h for h in hrefs), f"search for Kalman found: {hrefs[:10]}"
