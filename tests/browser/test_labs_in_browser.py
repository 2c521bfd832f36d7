"""The labs in a real browser: the same checks as the chapters' (test_notebooks_in_browser.py), in a file of
their own so that pytest-xdist's ``--dist loadfile`` runs them on the other worker, beside the chapters."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

_spec = importlib.util.spec_from_file_location("_browser_suite", Path(__file__).with_name("test_notebooks_in_browser.py"))
suite = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(suite)

pytestmark = pytest.mark.browser
# the same module-scoped fixtures: this file gets a JupyterLab server and a Chromium of its own
lab_server = suite.lab_server
browser = suite.browser


@pytest.mark.parametrize("notebook", suite.LABS, ids=[p.name for p in suite.LABS])
def test_lab_runs_in_jupyterlab(lab_server, browser, notebook):
    """The lab runs in JupyterLab: every cell, no error, every widget view, one control moved."""
    suite.test_notebook_runs_in_jupyterlab(lab_server, browser, notebook)
