"""Sphinx configuration of the course site. Built by ``tools/build_site.py`` (``make docs``), which lays out
the source folder (this file, the pages beside it and the generated ones) and runs ``sphinx-build -W``.

Offline: the theme's assets are in the package, MathJax is a local copy (``django-static-mathjax``, MathJax
3.2.2, Apache-2.0: its LICENSE is copied beside it), search is Sphinx's own index, notebooks are never executed.
"""

from __future__ import annotations

import importlib
import inspect
import json
from pathlib import Path

import mathjax  # django-static-mathjax: MathJax's release files as package data

import slamlab

HERE = Path(__file__).resolve().parent
XREF = json.loads((HERE / "xref.json").read_text(encoding="utf-8")) if (HERE / "xref.json").exists() else {
    "calls": {}, "titles": {}}

project = "slamlab"
author = "slamlab contributors"
copyright = "slamlab contributors"
release = version = slamlab.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_design",
]
exclude_patterns = ["_build", "**.ipynb_checkpoints", "xref.json"]
root_doc = "index"

# ---- warnings: every one is an error (-W); references to slamlab's own objects are checked (nitpicky),
# references to outside objects (numpy, scipy, typing, ...) are not: there is no intersphinx offline.
nitpicky = True
nitpick_ignore_regex = [(r"py:.*", r"(?!slamlab\b).*")]

# ---- notebooks: the stored outputs, never executed
nb_execution_mode = "off"
nb_output_stderr = "show"
myst_enable_extensions = ["dollarmath", "colon_fence"]  # no amsmath: a line starting \begin{pmatrix} inside $$ would end the paragraph
myst_dmath_double_inline = True  # $$...$$ inside a paragraph is display math, as in JupyterLab
myst_heading_anchors = 3

# ---- API reference
autodoc_member_order = "bysource"
# Signatures without annotations: the numpydoc Parameters sections give each type with its shape and unit, and
# thousands of annotation references (np.ndarray, float | None, ...) would each cost a search of the index.
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# ---- equations: a local MathJax, no CDN
MATHJAX_DIR = Path(mathjax.__file__).resolve().parent / "static" / "mathjax"
mathjax_path = "mathjax/tex-chtml.js"

# ---- HTML
html_theme = "pydata_sphinx_theme"
html_title = f"slamlab {release}"
html_static_path = ["_static"]
html_css_files = ["slamlab.css"]
html_favicon = "_static/favicon.svg"  # a site's own icon (else the browser asks for /favicon.ico and gets a 404)
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "header_links_before_dropdown": 4,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "secondary_sidebar_items": ["page-toc"],
    "use_edit_page_button": False,
}
html_context = {"default_mode": "auto"}  # light or dark as the reader's system says (empty: a console error)
html_show_sourcelink = False
html_copy_source = False


def _copy_mathjax(app, exc):
    """Copy MathJax's browser build (es5/) and its licence into _static/mathjax after a successful build."""
    if exc is not None or app.builder.format != "html":
        return
    from sphinx.util.fileutil import copy_asset

    target = Path(app.outdir) / "_static" / "mathjax"
    copy_asset(str(MATHJAX_DIR / "es5"), str(target))
    copy_asset(str(MATHJAX_DIR / "LICENSE"), str(target))


def _chapters_of(name: str) -> list[str]:
    return XREF["calls"].get(name, [])


def _add_chapters(app, what, name, obj, options, lines):
    """Below each API entry that a chapter's code calls: links to those chapters (runs after numpydoc)."""
    chapters = _chapters_of(name)
    if chapters:
        links = ", ".join(f":doc:`{XREF['titles'].get(c, c)} </chapters/{c}>`" for c in chapters)
        lines += ["", f"*Called in:* {links}", ""]


def _canonical(target: str):
    """The documented name of ``slamlab.x.y`` (a re-export, an alias or a module attribute), or None."""
    parts = target.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        try:
            for attr in parts[i:]:
                obj = getattr(obj, attr)
        except AttributeError:
            return None
        if inspect.ismodule(obj):
            return "module", obj.__name__
        if inspect.isfunction(obj) or inspect.isclass(obj):
            return "obj", f"{obj.__module__}.{obj.__qualname__}"
        return "data", ".".join(parts)
    return None


def _resolve_reexports(app, env, node, contnode):
    """Let ``slamlab.filters.kf_predict`` (a re-export) and short names inside a module find the entry where
    the object is documented (its defining module)."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"]
    candidates = []
    if target.startswith("slamlab."):
        candidates.append(target)
    else:
        module = node.get("py:module")
        while module:
            candidates.append(f"{module}.{target}")
            module = module.rpartition(".")[0]
    domain = env.get_domain("py")
    for cand in candidates:
        found = _canonical(cand)
        if found is None:
            continue
        kind, name = found
        if kind == "data":  # a constant that exists (no entry of its own): the name, unlinked
            return contnode
        role = "mod" if kind == "module" else "obj"
        if name in domain.objects or (kind == "module" and name in domain.modules):
            return domain.resolve_xref(env, node["refdoc"], app.builder, role, name, node, contnode)
    return None


def setup(app):
    app.connect("build-finished", _copy_mathjax)
    app.connect("autodoc-process-docstring", _add_chapters, priority=600)  # after numpydoc's (500)
    app.connect("missing-reference", _resolve_reexports)
    return {"parallel_read_safe": True}
