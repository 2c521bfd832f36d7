"""Every chapter and lab notebook in a real browser: JupyterLab (started as `make lab` starts it) in headless Chromium.

For each notebook: open it, wait for its kernel, run all cells, and check that every code cell ran,
that no cell wrote an error or to stderr, that every widget view rendered (no "Error displaying widget"),
that every image loaded; then move one slider or dropdown of the notebook's first widget and check that
its output area changes and shows no error. The notebook's kernel is shut down after its test.

The same run is also the reproducibility check (issue 22): the server, and so every kernel, runs under
``tools/check_reproducible.py``'s variant ``alt`` (another OpenBLAS kernel than the machine's, one BLAS,
OpenMP and OpenCV thread, no AVX-512), and every kernel starts with that tool's prelude (OpenCV's, numpy's
and Python's global random states moved: an IPython startup file). After Run All, the notebook's outputs
are read from JupyterLab's model and compared with the stored ones exactly as that tool and nbval compare
them (the same sanitiser; images and widget views skipped): a number that moves with the machine fails here,
while nbval checks the machine as it is. ``make reproducible`` runs the same check outside the browser.

Marker ``browser``. Needs Playwright (PyPI) and a Chromium (Debian's ``chromium`` package;
``playwright install`` cannot download browsers here): the suite skips, naming what is missing,
unless ``SLAMLAB_REQUIRE_BROWSER=1`` (CI sets it), which turns the skip into a failure.
The server runs on a free local port with a random token and with autosave off (a user-settings
folder of its own), so the notebooks on disk are never rewritten; it is stopped by its process group.
"""

from __future__ import annotations

import fcntl
import hashlib
import importlib.util
import json
import os
import re
import secrets
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
_spec = importlib.util.spec_from_file_location("_check_reproducible", ROOT / "tools" / "check_reproducible.py")
reproducible = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reproducible)
#: the machine set-up the browser's kernels run under (the main nbval run uses the machine as it is)
VARIANT = "alt"
#: The chapters here; the labs in test_labs_in_browser.py, so that `pytest -n 2 --dist loadfile` runs the two
#: halves on two workers at once (a file stays on one worker), each with a server of its own.
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
LABS = sorted((ROOT / "notebooks" / "labs").glob("*_lab.ipynb"))
CHROMIUM_CANDIDATES = ("/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
RUN_TIMEOUT_S = 240
SERVER_TIMEOUT_S = 90  # `make lab` until the server answers
KERNEL_TIMEOUT_S = 120  # notebook shown and its kernel started, connected and idle

pytestmark = pytest.mark.browser


def _unavailable(reason: str):
    if os.environ.get("SLAMLAB_REQUIRE_BROWSER", "").strip() not in ("", "0"):
        pytest.fail(f"{reason} (SLAMLAB_REQUIRE_BROWSER=1 makes this an error)", pytrace=False)
    pytest.skip(reason)


def _chromium() -> str:
    found = os.environ.get("SLAMLAB_CHROMIUM") or next((c for c in CHROMIUM_CANDIDATES if Path(c).exists()), None)
    if found is None:
        _unavailable(f"no Chromium found (looked for $SLAMLAB_CHROMIUM and {', '.join(CHROMIUM_CANDIDATES)}); "
                     "install Debian's `chromium` package")
    return found


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _make_venv_locked() -> None:
    """``make venv`` while holding a lock: pytest-xdist workers never install into one ``.venv`` at once.

    `make lab` depends on the venv target, which reinstalls when ``pyproject.toml`` or ``constraints.txt``
    is newer than the stamp; done here first under a lock, the venv is up to date when `make lab` checks it.
    """
    digest = hashlib.sha1(str(ROOT).encode()).hexdigest()[:12]
    lock_path = Path(tempfile.gettempdir()) / f"slamlab-make-venv-{digest}.lock"
    with lock_path.open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        done = subprocess.run(["make", "-s", "venv"], check=False, cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        pytest.fail(f"`make venv` failed:\n{done.stdout}\n{done.stderr}", pytrace=False)


def _wait_for_server(proc, base: str, token: str, deadline: float) -> bool:
    """Poll the server's status until it answers (True) or its process has exited (False)."""
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"{base}/api/status?token={token}", timeout=2) as r:
                if r.status == 200:
                    return True
        except OSError:
            pass
        if proc.poll() is not None:
            return False
        time.sleep(0.5)
    return False


def _stop(proc) -> None:
    """Stop `make lab` and the server and kernels under it (its own process group)."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
    try:
        proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


@pytest.fixture(scope="module")
def lab_server(tmp_path_factory):
    """`make lab` with options for a test: no browser, free port, token, autosave off; yields the base URL
    (see :func:`start_lab_server`)."""
    yield from start_lab_server(tmp_path_factory)


def start_lab_server(tmp_path_factory, kernel_startup: str = ""):
    """`make lab` with options for a test: no browser, free port, token, autosave off; yields the base URL.

    ``kernel_startup`` is more code for the kernels' IPython startup file (run before the first cell).

    Safe under pytest-xdist (each worker starts its own server): the venv is brought up to date under a
    lock, folders come from the worker's own temporary directory, and the server does not move to another
    port when its port was taken in the meantime (``port_retries=0``) but exits, and is started again on
    another free port.
    """
    if shutil.which("make") is None:
        _unavailable("`make` is not installed")
    settings = tmp_path_factory.mktemp("lab-settings")
    plugin = settings / "@jupyterlab" / "docmanager-extension"
    plugin.mkdir(parents=True)
    (plugin / "plugin.jupyterlab-settings").write_text(json.dumps({"autosave": False}))
    # every cell in the DOM (no windowing), so that every output is rendered and can be checked
    tracker = settings / "@jupyterlab" / "notebook-extension"
    tracker.mkdir(parents=True)
    (tracker / "tracker.jupyterlab-settings").write_text(json.dumps({"windowingMode": "none"}))
    workspaces = tmp_path_factory.mktemp("lab-workspaces")
    token = secrets.token_hex(16)
    # the kernels' IPython profile: a startup file runs the reproducibility prelude before the first cell
    ipython_dir = tmp_path_factory.mktemp("ipython")
    startup = ipython_dir / "profile_default" / "startup"
    startup.mkdir(parents=True)
    (startup / "00-slamlab-prelude.py").write_text(
        reproducible.PRELUDE + "\nimport os as _os; _os.environ['SLAMLAB_PRELUDE_RAN'] = '1'; del _os\n"
        + kernel_startup)
    env = {**os.environ, "MPLBACKEND": "module://matplotlib_inline.backend_inline", "SLAMLAB_PROGRESS": "0",
           "IPYTHONDIR": str(ipython_dir), **reproducible.variant_env(VARIANT)}
    log_path = tmp_path_factory.mktemp("lab-log") / "server.log"
    _make_venv_locked()
    deadline = time.monotonic() + SERVER_TIMEOUT_S
    proc = None
    with log_path.open("w") as log:
        try:
            for _attempt in range(3):
                port = _free_port()
                args = (f"--no-browser --ip=127.0.0.1 --port={port} --ServerApp.port_retries=0 "
                        f"--ServerApp.token={token} --LabApp.user_settings_dir={settings} "
                        f"--LabApp.workspaces_dir={workspaces} "
                        "--LabApp.expose_app_in_browser=True")  # window.jupyterapp: the tests read the kernel state
                proc = subprocess.Popen(["make", "-s", "lab", f"LAB_ARGS={args}"], cwd=ROOT, env=env, stdout=log,
                                        stderr=subprocess.STDOUT, start_new_session=True)
                base = f"http://127.0.0.1:{port}"
                if _wait_for_server(proc, base, token, deadline):
                    break
                _stop(proc)
                log.flush()
                if f"port {port} is already in use" not in log_path.read_text():
                    pytest.fail(f"`make lab` did not start a server: see {log_path}", pytrace=False)
            else:
                pytest.fail(f"`make lab` found its port taken three times: see {log_path}", pytrace=False)
            yield base, token
        finally:
            if proc is not None:
                _stop(proc)


@pytest.fixture(scope="module")
def browser():
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _unavailable("playwright is not installed (pip install playwright)")
    exe = _chromium()
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, args=CHROMIUM_ARGS)
        yield b
        b.close()


_WATCH_BUSY = """() => {
    window.__slamlabBusySeen = false;
    const s = document.querySelector('.jp-Notebook-ExecutionIndicator');
    new MutationObserver(() => { if (s.getAttribute('data-status') !== 'idle') window.__slamlabBusySeen = true; })
        .observe(s, {attributes: true});
}"""
_DONE = """() => window.__slamlabBusySeen
    && document.querySelector('.jp-Notebook-ExecutionIndicator').getAttribute('data-status') === 'idle'
    && ![...document.querySelectorAll('.jp-CodeCell .jp-InputPrompt')].some(e => e.textContent.includes('*'))"""


# The notebook at `path` is open and its session's kernel is connected and idle. Not the toolbar's
# execution indicator alone: its data-status is 'idle' from the moment the notebook is shown, before the
# server has started a kernel; JupyterLab runs a cell only if the session has a kernel, and clears it
# otherwise, so a Run All in that window ran nothing (issue 22: under load the kernel came 2-3 s later).
_KERNEL_READY = """(path) => {
    const app = window.jupyterapp;  // set once JupyterLab has started (the page may still be loading)
    if (!app || !app.shell) return false;
    const panel = [...app.shell.widgets('main')].find(w => w.context && w.context.path === path);
    const session = panel && panel.sessionContext;
    const kernel = session && session.isReady && session.session && session.session.kernel;
    return !!kernel && kernel.connectionStatus === 'connected' && kernel.status === 'idle'
        && !!panel.node.querySelector('.jp-Notebook-ExecutionIndicator') && !!panel.node.querySelector('.jp-CodeCell');
}"""


def _wait_for_kernel(page, path: str) -> None:
    """Wait until the notebook at ``path`` (relative to the server's root) is open and its kernel is idle."""
    page.wait_for_function(_KERNEL_READY, arg=path, timeout=KERNEL_TIMEOUT_S * 1000)


_CLEARED = """() => !document.querySelector('.jp-CodeCell .jp-OutputArea-output')
    && ![...document.querySelectorAll('.jp-CodeCell .jp-InputPrompt')].some(e => /\\d/.test(e.textContent))"""


def _run_all(page, path: str) -> None:
    """Clear the stored outputs, run every cell through the Run menu; wait until the kernel has been busy and no
    cell is queued or running. Cleared first, so that every output and execution count checked comes from this run."""
    _wait_for_kernel(page, path)
    page.get_by_role("menuitem", name="Edit", exact=True).click()
    page.get_by_role("menuitem", name="Clear Outputs of All Cells", exact=True).click()
    page.wait_for_function(_CLEARED, timeout=30_000)
    page.evaluate(_WATCH_BUSY)
    page.get_by_role("menuitem", name="Run", exact=True).click()
    page.get_by_role("menuitem", name="Run All Cells", exact=True).click()
    page.wait_for_function(_DONE, timeout=RUN_TIMEOUT_S * 1000)


def _problems(page) -> list[str]:
    return page.evaluate("""() => {
        const out = [];
        document.querySelectorAll('.jp-OutputArea-output[data-mime-type="application/vnd.jupyter.stderr"]')
            .forEach(e => out.push('stderr/error output: ' + (e.textContent.length <= 1500 ? e.textContent
                : e.textContent.slice(0, 300) + ' [...] ' + e.textContent.slice(-1200))));  // the end names the error
        document.querySelectorAll('.jp-OutputArea-output').forEach(e => {
            if (e.textContent.includes('Error displaying widget')) out.push('a widget view did not render');
        });
        document.querySelectorAll('.jp-OutputArea-output img').forEach(img => {
            if (!img.complete || img.naturalWidth === 0) out.push('an image did not load');
        });
        return out;
    }""")


def _move_first_control(page) -> str | None:
    """Change the first widget's first slider or dropdown; return what was moved, or None if it has none."""
    widget = page.locator(".widget-interact").first
    if widget.count() == 0:
        return None
    output = widget.locator(".widget-output").first
    before = output.inner_html()  # text, tables and figures (an image's data changes with the plot)
    page.evaluate(_WATCH_BUSY)
    select = widget.locator("select")
    handle = widget.locator(".noUi-handle")
    if handle.count():  # a slider first: one step costs least
        handle.first.focus()
        handle.first.press("ArrowRight")
        moved = "slider one step right"
    elif select.count():
        options = select.first.locator("option").all_inner_texts()
        current = select.first.evaluate("s => s.options[s.selectedIndex].text")
        target = next(o for o in options if o != current)
        select.first.select_option(label=target)
        moved = f"dropdown -> {target}"
    else:
        return None
    button = widget.locator("button")
    if button.count():  # a manual widget (long runs) runs on its button
        button.first.click()
        moved += ", then its run button"
    page.wait_for_function(_DONE, timeout=RUN_TIMEOUT_S * 1000)
    try:  # the output widget's view updates from comm messages, a moment after the kernel is idle
        page.wait_for_function("([el, old]) => el.innerHTML !== old", arg=[output.element_handle(), before],
                               timeout=30_000)
    except Exception as exc:
        raise AssertionError(f"moving the {moved} left the widget's output unchanged") from exc
    return moved


def _widget_outputs(page) -> str:
    """What the widget cells show (for a failure message): the first 200 characters of each."""
    return " | ".join(page.evaluate(
        "() => [...document.querySelectorAll('.jp-CodeCell')].filter(c => c.textContent.includes('explore_'))"
        ".map(c => (c.querySelector('.jp-OutputArea') || {textContent: '(no output area)'}).textContent.slice(0, 200))"))


def _check_notebook(page, base, token, notebook) -> None:
    rel = notebook.relative_to(ROOT / "notebooks").as_posix()
    # a workspace of its own, reset: only this notebook is open (no tab restored from an earlier page)
    page.goto(f"{base}/lab/workspaces/{notebook.stem}/tree/{rel}?reset&token={token}", timeout=60_000)
    _run_all(page, rel)
    _assert_every_cell_ran(page, notebook, rel)
    _assert_outputs_reproduce(page, notebook, rel)
    n_widgets = sum("explore_" in c for c in _code_sources(notebook))
    if n_widgets:  # a widget view renders after its cell has run: wait for all of them
        try:
            page.wait_for_function(f"() => document.querySelectorAll('.widget-interact').length >= {n_widgets}",
                                   timeout=60_000)
        except Exception as exc:
            raise AssertionError(f"{rel}: {n_widgets} widget view(s) expected; the widget cells show: "
                                 f"{_widget_outputs(page)}") from exc
    problems = _problems(page)
    assert not problems, f"{rel}: " + "; ".join(problems)
    if n_widgets:
        moved = _move_first_control(page)
        assert moved is not None, f"{rel}: its first widget has no slider or dropdown"
        problems = _problems(page)
        assert not problems, f"{rel} after moving a control ({moved}): " + "; ".join(problems)


def _assert_every_cell_ran(page, notebook: Path, rel: str) -> None:
    """Every code cell of the notebook shows an execution count: Run All ran all of them (the counts were cleared)."""
    expected = sum(bool(source.strip()) for source in _code_sources(notebook))  # JupyterLab skips empty cells
    counts = page.evaluate("() => [...document.querySelectorAll('.jp-CodeCell .jp-InputPrompt')]"
                           ".map(e => e.textContent.trim())")
    ran = sum(bool(re.fullmatch(r"\[\d+\]:", c)) for c in counts)
    if ran != expected:
        problems = _problems(page)
        raise AssertionError(f"{rel}: {ran} of {expected} code cells ran (prompts: {' '.join(counts)})"
                             + (f"; {'; '.join(problems)}" if problems else ""))


_NOTEBOOK_JSON = """(path) => {
    const panel = [...window.jupyterapp.shell.widgets('main')].find(w => w.context && w.context.path === path);
    return panel.context.model.toJSON();
}"""


def _assert_outputs_reproduce(page, notebook: Path, rel: str) -> None:
    """The outputs of this run (variant ``VARIANT``, prelude first) are the stored ones, as nbval compares them."""
    import nbformat

    fresh = nbformat.from_dict(page.evaluate(_NOTEBOOK_JSON, rel))
    stored = nbformat.read(notebook, as_version=4)
    diffs = reproducible.compare(stored, fresh, reproducible.sanitize_patterns())
    assert not diffs, (f"{rel}: outputs differ from the stored ones under variant {VARIANT!r} "
                       f"({reproducible.variant_env(VARIANT)}):\n" + "\n".join(diffs))


def _shut_down_sessions(base: str, token: str, path: str) -> None:
    """Shut down the server's sessions (and kernels) of the notebook at ``path``: the next test starts clean."""
    with urllib.request.urlopen(f"{base}/api/sessions?token={token}", timeout=10) as r:
        sessions = json.load(r)
    for session in sessions:
        if session.get("path") == path:
            request = urllib.request.Request(f"{base}/api/sessions/{session['id']}?token={token}", method="DELETE")
            urllib.request.urlopen(request, timeout=30).close()


def test_make_lab_sends_widget_messages_to_the_main_thread(lab_server):
    """`make lab` turns JupyterLab's comms over kernel subshells off: with them, a widget's callback runs on a
    thread of its own and can draw while a cell draws, and matplotlib's shared mathtext parser then fails (seen
    here: a ParseException after moving notebook 08's first slider)."""
    base, token = lab_server
    url = f"{base}/lab/api/settings/@jupyterlab/apputils-extension:kernels-settings?token={token}"
    with urllib.request.urlopen(url, timeout=30) as r:
        schema = json.load(r)["schema"]
    assert schema["properties"]["commsOverSubshells"]["default"] == "disabled"


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs_in_jupyterlab(lab_server, browser, notebook):
    """The notebook runs in JupyterLab: every cell, no error, every widget view, one control moved."""
    base, token = lab_server
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    try:
        _check_notebook(page, base, token, notebook)
    finally:
        page.close()
        _shut_down_sessions(base, token, notebook.relative_to(ROOT / "notebooks").as_posix())


def _code_sources(path: Path) -> list[str]:
    nb = json.loads(path.read_text(encoding="utf-8"))
    return ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]


_PROGRESS_CELL = """import os
os.environ.pop("SLAMLAB_PROGRESS", None)   # a student's kernel: no setting, bars on
import slamlab as sl
noise = sl.studies.hough.run_noise_study((0.0, 0.1), 3, n_poses=20)
print("rows", len(noise.runs), "coretype", os.environ.get("OPENBLAS_CORETYPE"), "prelude", os.environ.get("SLAMLAB_PRELUDE_RAN"))"""


def test_progress_bar_is_a_widget_in_jupyterlab(lab_server, browser):
    """A library loop shows its tqdm.auto bar as a widget in JupyterLab (not as stderr text), and the
    bar goes away when the loop ends (``leave=False``); the notebook is a scratch file, removed after.
    The same kernel shows that the server's kernels run under the variant and started with the prelude."""
    base, token = lab_server
    scratch = ROOT / "notebooks" / f"zz_progress_check_{secrets.token_hex(4)}.ipynb"
    cell = {"cell_type": "code", "execution_count": None, "id": "c0", "metadata": {}, "outputs": [],
            "source": _PROGRESS_CELL}
    nb = {"cells": [cell], "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3",
                                                       "language": "python"}}, "nbformat": 4, "nbformat_minor": 5}
    scratch.write_text(json.dumps(nb), encoding="utf-8")
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    try:
        page.goto(f"{base}/lab/workspaces/{scratch.stem}/tree/{scratch.name}?reset&token={token}", timeout=60_000)
        _wait_for_kernel(page, scratch.name)
        page.evaluate(_WATCH_BUSY)
        page.locator(".jp-CodeCell .cm-content").first.click()
        page.keyboard.press("Shift+Enter")
        bar = page.wait_for_selector(".jp-OutputArea-output .widget-hprogress", timeout=120_000)
        label = page.locator(".jp-OutputArea-output").first.inner_text().replace("\u2007", " ")  # tqdm pads with figure spaces
        assert "Hough SLAM noise study" in label  # the bar's label
        page.wait_for_function(_DONE, timeout=RUN_TIMEOUT_S * 1000)
        text = page.locator(".jp-OutputArea-output").last.inner_text()
        assert "rows 6" in text
        # the kernel runs under the reproducibility variant, its prelude first (see the module docstring)
        assert f"coretype {reproducible.variant_env(VARIANT)['OPENBLAS_CORETYPE']} prelude 1" in text, text
        assert not bar.is_visible()
        assert not _problems(page)
    finally:
        page.close()
        _shut_down_sessions(base, token, scratch.name)
        scratch.unlink(missing_ok=True)
