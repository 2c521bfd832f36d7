#!/usr/bin/env python
"""Build the course site (``make docs``): static HTML in ``build/site/`` from the repository's own files.

Usage::

    python tools/build_site.py [--out build/site] [--work build/site-work]

Sphinx needs every page inside one source folder, so this script first lays out ``<work>/src``:
``docs/site/`` (``conf.py``, the hand-written pages, ``_static``), the README as the overview, every
chapter notebook with its **stored** outputs (myst-nb renders them; nothing is executed), the student
version of every lab (``tools/labs.py student``, as ``make student``), the instructor guide with each
lab's time plan and points, one API page per subpackage (autodoc + numpydoc), ``docs/*.md`` and
``environment.md``, and the data pages generated from slamlab's data registry (``slamlab/data/registry.json``:
each set's source, licence, citation and files with their upstream URLs and sha256; the data themselves are
never read). Then it runs ``sphinx-build -W --keep-going`` (warnings are errors).

Cross-references both ways come from the notebooks' code: every ``sl.<pkg>.<name>`` (also through an alias
such as ``L = sl.localisation``, and ``from slamlab… import``) in a chapter's code cells is resolved to the
object it names; the chapter gets a box linking those objects to their API entries, and ``xref.json`` tells
``conf.py`` which chapters to list under each API entry and on each subpackage's page.

A widget's output cannot run on a static page: its stored output (the widget's text form) is kept, with a
note saying that it needs a running kernel and what it lets you explore (the ``explore_*`` function's summary).
"""

from __future__ import annotations

import argparse
import ast
import importlib
import inspect
import json
import os
import pkgutil
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SITE_SRC = ROOT / "docs" / "site"
WIDGET_MIME = "application/vnd.jupyter.widget-view+json"
#: the docs pages taken as they are (path in the repository -> page name)
DOC_PAGES = {"docs/benchmarks.md": "benchmarks", "environment.md": "environment", "docs/notation.md": "notation"}
#: private modules whose docstring public docstrings refer to (``progress=`` is explained in slamlab._progress)
PRIVATE_DOCUMENTED = ["slamlab._progress"]
#: a docstring's source section: the last parenthesised group of its first line, e.g. "(000 §1.2.1)"
_SECTION = re.compile(r"\(([^()]*(?:§|\b00\d\b|ours|[Ee]q)[^()]*)\)\s*\.?\s*$")


# ---------------------------------------------------------------- the public API (as tests/test_docstrings.py)
def public_modules() -> list[str]:
    """Every public module of slamlab (no dotted component after ``slamlab`` starts with ``_``)."""
    import slamlab

    names = ["slamlab"]
    for info in pkgutil.walk_packages(slamlab.__path__, "slamlab."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            names.append(info.name)
    return names


def public_objects(module_name: str) -> list[tuple[str, object]]:
    """The public functions and classes defined in ``module_name`` (its own, not imported ones), by name."""
    module = importlib.import_module(module_name)
    out = []
    for attr, obj in sorted(vars(module).items()):
        if attr.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
            continue
        if getattr(obj, "__module__", None) == module_name:
            out.append((f"{module_name}.{attr}", obj))
    return out


def api_pages() -> dict[str, list[str]]:
    """Page name -> the modules documented on it: one page per subpackage, top-level modules on ``slamlab``."""
    import slamlab

    pages: dict[str, list[str]] = {"slamlab": ["slamlab"]}
    modules = public_modules()
    for info in pkgutil.iter_modules(slamlab.__path__):
        if info.name.startswith("_"):
            continue
        if info.name == "studies":  # the studies layer: its own page, then one page per chapter's studies
            import slamlab.studies

            pages["studies"] = ["slamlab.studies"]
            for sub in pkgutil.iter_modules(slamlab.studies.__path__):
                name = f"studies.{sub.name}"
                pages[name] = [m for m in modules if m == f"slamlab.{name}" or m.startswith(f"slamlab.{name}.")]
        elif info.ispkg:
            pages[info.name] = [m for m in modules
                                if m == f"slamlab.{info.name}" or m.startswith(f"slamlab.{info.name}.")]
        else:
            pages["slamlab"].append(f"slamlab.{info.name}")
    return pages


def canonical_name(obj) -> str | None:
    """``module.qualname`` of a function, class or method; None for anything else."""
    if not (inspect.isfunction(obj) or inspect.isclass(obj) or inspect.ismethod(obj)):
        return None
    module, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if not module or not qualname or "<" in qualname:
        return None
    return f"{module}.{qualname}"


# ---------------------------------------------------------------- what a notebook's code calls
def _dotted(node: ast.AST) -> str | None:
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if isinstance(node, ast.Name):
        parts.append(node.id)
        return ".".join(reversed(parts))
    return None


def _resolve(dotted: str):
    """The object ``slamlab.a.b.c`` names (its longest importable/gettable prefix), with the spelling used."""
    parts = dotted.split(".")
    obj, found = None, None
    for i in range(1, len(parts) + 1):
        name = ".".join(parts[:i])
        if obj is None or inspect.ismodule(obj):
            try:
                obj = importlib.import_module(name)
                found = (name, obj)
                continue
            except ImportError:
                if obj is None:
                    return None
        if not hasattr(obj, parts[i - 1]):
            break
        obj = getattr(obj, parts[i - 1])
        found = (name, obj)
    return found


def slamlab_calls(code_cells: list[str]) -> dict[str, str]:
    """Canonical name -> the spelling first used, for every slamlab function/class/method the cells name."""
    aliases: dict[str, str] = {}
    found: dict[str, str] = {}
    for source in code_cells:
        source = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
        try:
            tree = ast.parse(source)
        except SyntaxError:
            continue
        for node in ast.walk(tree):  # the aliases first: import slamlab as sl, from slamlab.x import y, L = sl.x
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] == "slamlab":
                        aliases[a.asname or a.name.split(".")[0]] = a.name if a.asname else "slamlab"
            elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "slamlab":
                for a in node.names:
                    aliases[a.asname or a.name] = f"{node.module}.{a.name}"
            elif isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
                dotted = _dotted(node.value)
                if dotted and dotted.split(".")[0] in aliases:
                    full = aliases[dotted.split(".")[0]] + dotted[len(dotted.split(".")[0]):]
                    hit = _resolve(full)
                    if hit and inspect.ismodule(hit[1]):
                        aliases[node.targets[0].id] = hit[0]
        for node in ast.walk(tree):
            if not isinstance(node, (ast.Attribute, ast.Name)):
                continue
            dotted = _dotted(node)
            if not dotted or dotted.split(".")[0] not in aliases:
                continue
            root = dotted.split(".")[0]
            hit = _resolve(aliases[root] + dotted[len(root):])
            if hit is None:
                continue
            name = canonical_name(hit[1])
            if name and name.startswith("slamlab.") and name not in found:
                found[name] = dotted
    return found


# ---------------------------------------------------------------- pages
def _read_nb(path: Path) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


def _md_cell(text: str, cell_id: str) -> dict:
    return {"cell_type": "markdown", "id": cell_id, "metadata": {}, "source": text}


#: a Markdown link to a file of the repository, relative to notebooks/ or notebooks/labs/
_LINK = re.compile(r"\]\((\.\./[^)\s#]+)(#[^)\s]*)?\)")
#: repository files that are pages of the site (path in the repository -> page, from the site's root)
_PAGE_OF = {**{k: f"/{v}" for k, v in DOC_PAGES.items()}, "README.md": "/overview"}


def _fix_links(text: str, nb_dir: Path, src: Path) -> str:
    """Links to repository files: a page of the site becomes a link to that page; any other file is copied
    under ``repo/`` of the site (a download link); a link to a notebook goes to its page."""
    def repl(m):
        target = (nb_dir / m.group(1)).resolve()
        try:
            rel = target.relative_to(ROOT).as_posix()
        except ValueError:
            return m.group(0)
        anchor = m.group(2) or ""
        if rel in _PAGE_OF:
            return f"]({_PAGE_OF[rel]}.md{anchor})" if rel.endswith(".md") else f"]({_PAGE_OF[rel]}{anchor})"
        if rel.startswith("notebooks/") and rel.endswith(".ipynb"):
            page = ("/labs/" if "/labs/" in rel else "/chapters/") + Path(rel).stem
            return f"]({page}.ipynb{anchor})"
        if target.is_file():
            copy = src / "repo" / rel
            copy.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(target, copy)
            return f"](/repo/{rel})"
        return m.group(0)
    return _LINK.sub(repl, text)


def _fix_nb_links(nb: dict, nb_dir: Path, src: Path) -> None:
    for cell in nb["cells"]:
        if cell["cell_type"] == "markdown":
            cell["source"] = _fix_links("".join(cell["source"]), nb_dir, src)


def _code_sources(nb: dict) -> list[str]:
    return ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]


def _title(nb: dict, fallback: str) -> str:
    for cell in nb["cells"]:
        if cell["cell_type"] == "markdown":
            m = re.search(r"^#\s+(.+)$", "".join(cell["source"]), re.MULTILINE)
            if m:
                return m.group(1).strip()
    return fallback


def _summary(obj) -> str:
    doc = inspect.getdoc(obj) or ""
    return doc.strip().split("\n\n")[0].replace("\n", " ")


def _widget_note(cell_source: str, calls: dict[str, str]) -> str:
    """The note put after a widget's stored output: it needs a kernel, and what it lets you explore."""
    explored = []
    for name, spelled in calls.items():
        if name.rsplit(".", 1)[-1].startswith("explore_") and name.rsplit(".", 1)[-1] in cell_source:
            obj = _resolve(name)[1]
            explored.append(f"{{py:obj}}`{spelled} <{name}>`: {_md_escape(_summary(obj))}")
    what = (" It lets you explore: " + "; ".join(explored)) if explored else ""
    return ("```{admonition} Interactive widget: needs a running kernel\n:class: tip\n"
            "On this static page the widget shows only its stored text form (above). Open the notebook in "
            "JupyterLab (`make lab`) and run it to move its controls." + what + "\n```")


def _md_escape(text: str) -> str:
    return text.replace("*", r"\*").replace("_", r"\_").replace("$", r"\$")


def chapter_page(src: Path, dst: Path, lab: str | None) -> dict[str, str]:
    """Write the chapter ``src`` for the site; return the slamlab objects its code calls (canonical -> spelling)."""
    nb = _read_nb(src)
    _fix_nb_links(nb, src.parent, dst.parent.parent)
    calls = slamlab_calls(_code_sources(nb))
    cells = []
    for cell in nb["cells"]:
        widget = cell["cell_type"] == "code" and any(WIDGET_MIME in o.get("data", {}) for o in cell.get("outputs", []))
        if widget:
            for o in cell["outputs"]:
                o.get("data", {}).pop(WIDGET_MIME, None)
        cells.append(cell)
        if widget:
            cells.append(_md_cell(_widget_note("".join(cell["source"]), calls),
                                  f"site-widget-note-{len(cells)}"))
    links = ", ".join(f"{{py:obj}}`{spelled} <{name}>`" for name, spelled in sorted(calls.items(), key=lambda kv: kv[1]))
    box = "```{admonition} slamlab in this chapter\n:class: seealso\n"
    if lab:
        box += f"The lab: {{doc}}`/labs/{lab}`.\n\n"
    box += (f"The code cells below call ({len(calls)}, each linked to its API entry): {links}\n```"
            if calls else "The code cells below call no slamlab function.\n```")
    first_md = next((i for i, c in enumerate(cells) if c["cell_type"] == "markdown"), -1)
    cells.insert(first_md + 1, _md_cell(box, "site-slamlab-calls"))
    nb["cells"] = cells
    dst.write_text(json.dumps(nb, ensure_ascii=False, indent=1), encoding="utf-8")
    return calls


def lab_page(src: Path, dst: Path, chapter: str | None) -> None:
    nb = _read_nb(src)
    _fix_nb_links(nb, ROOT / "notebooks" / "labs", dst.parent.parent)
    note = ("```{admonition} Student version\n:class: seealso\n"
            "This is the lab as students get it (`make student`: solutions removed). Run it in JupyterLab; "
            "each check cell says *passed* or shows the first failing case."
            + (f" The chapter: {{doc}}`/chapters/{chapter}`." if chapter else "")
            + " Instructors: {doc}`/labs/instructor`.\n```")
    first_md = next((i for i, c in enumerate(nb["cells"]) if c["cell_type"] == "markdown"), -1)
    nb["cells"].insert(first_md + 1, _md_cell(note, "site-student-note"))
    dst.write_text(json.dumps(nb, ensure_ascii=False, indent=1), encoding="utf-8")


def _time_plan(nb: dict) -> tuple[str, str]:
    """The lab's time-plan sentence and its total (``about N minutes in all``), from its first cell."""
    for cell in nb["cells"]:
        text = " ".join("".join(cell["source"]).split())
        m = re.search(r"\*\*Time plan[^*]*\*\*\s*(.*?in all\.)", text)
        if m:
            total = re.search(r"about (\d+) minutes in all", m.group(1))
            return m.group(1), (total.group(1) if total else "")
    return "", ""


def _points(nb: dict) -> float:
    return sum(float(c.get("metadata", {}).get("nbgrader", {}).get("points", 0) or 0) for c in nb["cells"])


def instructor_page(labs: list[Path], chapters: dict[str, str]) -> str:
    rows = []
    for lab in labs:
        nb = _read_nb(lab)
        plan, total = _time_plan(nb)
        nn = lab.name[:2]
        chapter = chapters.get(nn)
        rows.append(f"| {{doc}}`{nn} <{lab.stem}>` | {_md_escape(_title(nb, lab.stem))} | "
                    + (f"{{doc}}`{nn} </chapters/{chapter}>`" if chapter else "—")
                    + f" | {total} | {_points(nb):g} | {_md_escape(plan)} |")
    intro = (SITE_SRC / "instructor.md").read_text(encoding="utf-8")
    table = ("| lab | title | chapter | minutes | points | time plan (from the lab) |\n"
             "|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    rubrics = []
    for lab in labs:
        nb = _read_nb(lab)
        rubrics.append(f"### {{doc}}`{lab.name[:2]} <{lab.stem}>`: {_md_escape(_title(nb, lab.stem))}\n")
        for part, points, text in lab_rubrics(nb):
            rubrics.append(f"- **{part}** ({points:g} points). {text}")
        rubrics.append("")
    return intro.replace("<!-- LAB TABLE -->", table).replace("<!-- RUBRICS -->", "\n".join(rubrics))


#: The first paragraph of a hand-graded answer cell: "**Rubric (N points).** 1 point: ...; ..."
_RUBRIC = re.compile(r"^\*\*Rubric \((\d+(?:\.\d+)?) points?\)\.\*\*\s*(.*?)(?:\n\s*\n|$)", re.DOTALL)


def lab_rubrics(nb: dict) -> list[tuple[str, float, str]]:
    """The rubric of every hand-graded answer of a lab: (question, points, the rubric's text) in order.

    A hand-graded cell is a markdown cell with nbgrader's ``solution`` and ``grade``; its first paragraph is the
    rubric (``**Rubric (N points).** ...``), the rest the model answer, which the site does not publish.
    """
    out = []
    for c in nb["cells"]:
        meta = c.get("metadata", {}).get("nbgrader", {})
        if c["cell_type"] != "markdown" or not (meta.get("solution") and meta.get("grade")):
            continue
        source = "".join(c["source"]) if isinstance(c["source"], list) else c["source"]
        m = _RUBRIC.match(source.strip())
        if m is None:
            raise ValueError(f"{meta.get('grade_id')}: a hand-graded answer starts with **Rubric (N points).**")
        part = meta["grade_id"].split("_")[1]
        label = "open investigation" if part == "inv" else part.upper()
        out.append((label, float(meta.get("points", 0)), " ".join(m.group(2).split())))
    return out


def _rst_escape(text: str) -> str:
    return re.sub(r"([*`|_\\])", r"\\\1", text)


def _members(module: str) -> list[str]:
    """autodoc directives for the public functions and classes defined in ``module`` (exactly the objects the
    docstring test walks: not imported ones, whatever ``__all__`` says)."""
    out = []
    for name, obj in public_objects(module):
        if inspect.isclass(obj):
            out += [f".. autoclass:: {name}", "   :members:", "   :undoc-members:", ""]
        else:
            out += [f".. autofunction:: {name}", ""]
    return out


def api_page(page: str, modules: list[str], xref: dict[str, list[str]], chapter_titles: dict[str, str]) -> str:
    """One API page (rst): the package's docstring, a table of its functions and classes with their source
    section and the chapters that call them, then every module's members (autodoc + numpydoc)."""
    title = "slamlab (top level)" if page == "slamlab" else f"slamlab.{page}"
    out = [title, "=" * len(title), ""]
    lead = "slamlab" if page == "slamlab" else f"slamlab.{page}"
    out += [f".. automodule:: {lead}", ""]
    if page == "slamlab":  # private modules that public docstrings point to: their docstring only
        for private in PRIVATE_DOCUMENTED:
            out += [private, "-" * len(private), "", f".. automodule:: {private}", ""]
    rows = []
    users: set[str] = set()
    for module in modules:
        for name, obj in public_objects(module):
            section = _SECTION.search((inspect.getdoc(obj) or "").split("\n")[0])
            chapters = xref.get(name, [])
            for cls_member in [k for k in xref if k.startswith(name + ".")]:
                chapters = sorted(set(chapters) | set(xref[cls_member]))
            users.update(chapters)
            rows.append((name, section.group(1) if section else "", chapters))
    if users:
        out += ["Chapters that call this package: "
                + ", ".join(f":doc:`{chapter_titles[c]} </chapters/{c}>`" for c in sorted(users)) + ".", ""]
    if rows:  # a package of subpackages only (slamlab.studies) has no table of its own
        out += [".. list-table::", "   :header-rows: 1", "   :widths: 40 25 35", "",
                "   * - function or class", "     - source section", "     - called in chapters"]
    for name, section, chapters in rows:
        out += [f"   * - :py:obj:`~{name}`", f"     - {_rst_escape(section) if section else '—'}",
                "     - " + (", ".join(f":doc:`{c[:2]} </chapters/{c}>`" for c in chapters) if chapters else "—")]
    out.append("")
    for module in modules:
        if module == lead:
            if public_objects(module):
                heading = f"{module} (package)"
                out += [heading, "-" * len(heading), "", f".. currentmodule:: {module}", "", *_members(module)]
            continue
        out += [module, "-" * len(module), "", f".. automodule:: {module}", ""]
        out += _members(module)
    return "\n".join(out)


def _md_text(text: str) -> str:
    """Plain ``text`` as Markdown in a table cell or list item: no table split at ``|``, no HTML read into
    ``<x>`` (a source such as ``images/<sequence>/``), no emphasis or maths."""
    for ch in "\\|<*_$":
        text = text.replace(ch, "\\" + ch)
    return text.replace("\n", " ")


def _code_cell(text: str) -> str:
    """``text`` as inline code in a table cell (a code span keeps backslashes; only ``|`` is escaped)."""
    return "`" + text.replace("|", "\\|") + "`"


def _derivation(f) -> str:
    """How a registered file is made from its upstream file ('' for a byte-for-byte copy)."""
    from slamlab.data.registry import format_size

    if f.derive is None:
        return ""
    kind = f.derive.get("kind")
    if kind == "lines":
        how = f"first {f.derive['count']} lines of the upstream file"
    elif kind == "png_from_pnm":
        how = "the upstream PPM/PGM stored as lossless PNG; same pixels"
    else:
        how = f"derived from the upstream file ({kind})"
    if f.upstream_sha256:
        size = f", {format_size(f.upstream_size)}" if f.upstream_size is not None else ""
        how += f" (upstream sha256 `{f.upstream_sha256}`{size})"
    return how


def _url_label(url: str) -> str:
    """A link's text: the file's path in its repository for a raw GitHub URL, else the URL."""
    parts = url.split("/", 3)[3].split("/") if url.startswith("https://raw.githubusercontent.com/") else []
    return "/".join(parts[3:]) if len(parts) > 3 else url


def data_set_page(s) -> str:
    """The site page of one registered data set (:class:`slamlab.data.DataSet`) as MyST Markdown."""
    from slamlab.data.registry import format_size

    out = [f"# {s.name}", "", _md_text(s.title), "",
           f"- **Source:** {_md_text(s.source)}",
           f"- **Licence:** {_md_text(s.licence)}",
           f"- **Cite:** {_md_text(s.citation)}",
           f"- **Size:** {len(s.files)} file{'' if len(s.files) == 1 else 's'}, {format_size(s.size)}"]
    if s.note:
        out.append(f"- **Note:** {_md_text(s.note)}")
    out += ["", "## How to get it", "",
            ("The notebooks fetch what they need on first use; to fetch the whole set beforehand (into the cache, "
             "unless `$SLAMLAB_DATA` or `../shared/data` already holds it):"), "",
            "```", f"python -m slamlab.data fetch {s.name}", "```", "",
            f"`python -m slamlab.data verify {s.name}` re-hashes the files found against the table below.", "",
            "## Files", "",
            "| file | size | upstream (pinned commit) | sha256 | made from the upstream file |",
            "|---|---|---|---|---|"]
    for f in s.files:
        out.append(f"| {_code_cell(f.path)} | {format_size(f.size)} | [{_code_cell(_url_label(f.url))}]({f.url}) "
                   f"| `{f.sha256}` | {_derivation(f) or 'as is'} |")
    return "\n".join(out) + "\n"


def data_pages(dst: Path) -> list[str]:
    """The data pages, from slamlab's registry only: an index with the table of sets, one page per set; their names."""
    from slamlab.data.registry import data_table_markdown, registry

    dst.mkdir(parents=True, exist_ok=True)
    reg = registry()
    names = list(reg.set_names)
    for s in reg.sets:
        (dst / f"{s.name}.md").write_text(data_set_page(s), encoding="utf-8")
    intro = (SITE_SRC / "data.md").read_text(encoding="utf-8").rstrip("\n")
    table = re.sub(r"(?<!\\)<", r"\\<", data_table_markdown(reg))  # images/<sequence>/ is not HTML
    (dst / "index.md").write_text(intro + "\n\n" + table + "\n```{toctree}\n:maxdepth: 1\n\n" + "\n".join(names)
                                  + "\n```\n", encoding="utf-8")
    return names


# ---------------------------------------------------------------- the build
def stage(work: Path, student_dir: Path | None = None) -> Path:
    """Lay out the Sphinx source folder ``work/src``; return it."""
    src = work / "src"
    if src.exists():
        shutil.rmtree(src)
    shutil.copytree(SITE_SRC, src, ignore=shutil.ignore_patterns("instructor.md", "data.md", "__pycache__"))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    (src / "overview.md").write_text(re.sub(r"\A# slamlab\n", "# Overview: slamlab\n", readme), encoding="utf-8")
    for repo_path, page in DOC_PAGES.items():
        if (ROOT / repo_path).exists():
            (src / f"{page}.md").write_text((ROOT / repo_path).read_text(encoding="utf-8"), encoding="utf-8")
    # chapters
    chapters = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    labs_src = sorted((ROOT / "notebooks" / "labs").glob("*_lab.ipynb"))
    lab_of = {p.name[:2]: p.stem for p in labs_src}
    chapter_of = {p.name[:2]: p.stem for p in chapters}
    (src / "chapters").mkdir()
    xref: dict[str, list[str]] = {}
    titles = {}
    spelled: dict[str, dict[str, str]] = {}
    for nb in chapters:
        calls = chapter_page(nb, src / "chapters" / nb.name, lab_of.get(nb.name[:2]))
        spelled[nb.stem] = calls
        titles[nb.stem] = _title(_read_nb(nb), nb.stem)
        for name in calls:
            xref.setdefault(name, []).append(nb.stem)
    (src / "chapters" / "index.md").write_text(
        "# Chapters\n\nEach chapter is a notebook shown with its stored outputs (the ones `nbval` checks); "
        "run it yourself in JupyterLab (`make lab`).\n\n```{toctree}\n:maxdepth: 1\n\n"
        + "\n".join(p.stem for p in chapters) + "\n```\n", encoding="utf-8")
    # labs: the student versions
    if student_dir is None:
        student_dir = work / "student"
    course = work / "course"
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "labs.py"), "student", "--out", str(student_dir),
                           "--course", str(course)], cwd=ROOT, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"tools/labs.py student failed:\n{done.stdout}\n{done.stderr}")
    (src / "labs").mkdir()
    student = sorted(student_dir.glob("*_lab.ipynb"))
    if [p.name for p in student] != [p.name for p in labs_src]:
        raise SystemExit(f"student versions {[p.name for p in student]} != labs {[p.name for p in labs_src]}")
    for nb in student:
        lab_page(nb, src / "labs" / nb.name, chapter_of.get(nb.name[:2]))
    (src / "labs" / "instructor.md").write_text(instructor_page(labs_src, chapter_of), encoding="utf-8")
    (src / "labs" / "index.md").write_text(
        "# Labs\n\nThe student version of every lab (solutions removed, as `make student` writes them), and the "
        "guide for instructors.\n\n```{toctree}\n:maxdepth: 1\n\ninstructor\n"
        + "\n".join(p.stem for p in student) + "\n```\n", encoding="utf-8")
    # API reference
    (src / "api").mkdir()
    pages = api_pages()
    for page, modules in pages.items():
        (src / "api" / f"{page}.rst").write_text(api_page(page, modules, xref, titles), encoding="utf-8")
    (src / "api" / "index.md").write_text(
        "# API reference\n\nGenerated from the docstrings (numpydoc): one page per subpackage, each with a table of "
        "its functions and classes, their source section (000, 002, 003, 004 and the section, or *ours*) and the "
        "chapters that call them.\n\n```{toctree}\n:maxdepth: 1\n\n"
        + "\n".join(pages) + "\n```\n", encoding="utf-8")
    (src / "xref.json").write_text(json.dumps({"calls": xref, "titles": titles, "spelled": spelled}, indent=1), encoding="utf-8")
    data_pages(src / "data")
    return src


def link_code(out: Path, spelled: dict[str, dict[str, str]]) -> int:
    """In each chapter's HTML, link every ``sl.pkg.name`` of the code cells to its API entry (the href that the
    chapter's "slamlab in this chapter" box already has for it); return the number of links made."""
    made = 0
    for chapter, calls in spelled.items():
        page = out / "chapters" / f"{chapter}.html"
        html = page.read_text(encoding="utf-8")
        for name, dotted in sorted(calls.items(), key=lambda kv: -len(kv[1])):  # longest spelling first
            href = re.search(rf'<a class="reference internal" href="([^"]+)" title="{re.escape(name)}"', html)
            if not href:
                continue
            parts = [rf'<span class="n\w*">{re.escape(p)}</span>' for p in dotted.split(".")]
            token = re.compile(r'(?<!">)(' + r'<span class="o">\.</span>'.join(parts) + r')(?!<span class="o">\.</span>)')
            html, n = token.subn(rf'<a class="slamlab-code-ref" href="{href.group(1)}" title="{name}">\1</a>', html)
            made += n
        page.write_text(html, encoding="utf-8")
    return made


def build(out: Path, work: Path, student_dir: Path | None = None, quiet: bool = True) -> float:
    """Stage and build; return the seconds taken. Raises SystemExit when Sphinx warns or fails."""
    start = time.perf_counter()
    src = stage(work, student_dir)
    if out.exists():
        shutil.rmtree(out)
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-d", str(work / "doctrees"),
           str(src), str(out)]
    if quiet:
        cmd.insert(3, "-q")
    env = {**os.environ, "MPLBACKEND": "Agg", "SLAMLAB_PROGRESS": "0"}
    done = subprocess.run(cmd, cwd=ROOT, env=env, check=False)
    if done.returncode != 0:
        raise SystemExit(f"sphinx-build failed (exit {done.returncode}): see the warnings above")
    link_code(out, json.loads((src / "xref.json").read_text(encoding="utf-8"))["spelled"])
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "site")
    parser.add_argument("--work", type=Path, default=ROOT / "build" / "site-work")
    args = parser.parse_args(argv)
    seconds = build(args.out.resolve(), args.work.resolve())
    pages = sum(1 for p in args.out.rglob("*.html") if "_static" not in p.parts)
    print(f"site: {args.out / 'index.html'} ({pages} pages, {seconds:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
