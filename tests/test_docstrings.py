"""Every public function, class and method of slamlab documents each of its parameters in a numpydoc
``Parameters`` section (classes: ``Parameters`` or ``Attributes``), named as in its signature (issue 23; the
course site's API reference is generated from these sections).

Public: a module whose dotted path has no component starting with ``_``; a function or class defined there
(``__module__`` is the module) whose name does not start with ``_``; a method in such a class's own ``__dict__``
whose name does not start with ``_`` (classmethods and staticmethods included). ``self``/``cls`` are not parameters; ``*args``/``**kwargs`` may be
written with or without their stars.
"""
from __future__ import annotations

import importlib
import inspect
import pkgutil
import re

import slamlab

_ENTRY = re.compile(r"^\*{0,2}[A-Za-z_][A-Za-z0-9_]*(\s*,\s*\*{0,2}[A-Za-z_][A-Za-z0-9_]*)*\s*(:.*)?$")


def documented_names(doc: str, sections=("Parameters",)) -> set[str] | None:
    """Names listed in the given numpydoc sections of ``doc``; None when none of the sections exists."""
    lines = doc.splitlines()
    names: set[str] = set()
    found = False
    i = 0
    while i < len(lines) - 1:
        head, rule = lines[i], lines[i + 1]
        if head.strip() in sections and re.fullmatch(r"\s*-{3,}\s*", rule) and len(rule.strip()) >= len(head.strip()):
            found = True
            base = len(head) - len(head.lstrip())
            j = i + 2
            while j < len(lines):
                line = lines[j]
                if j + 1 < len(lines) and re.fullmatch(r"\s*-{3,}\s*", lines[j + 1]) and line.strip():
                    break  # next section header
                if line.strip() and len(line) - len(line.lstrip()) == base and _ENTRY.match(line.strip()):
                    for n in line.split(":", 1)[0].split(","):
                        names.add(n.strip().lstrip("*"))
                j += 1
            i = j
        else:
            i += 1
    return names if found else None


def _function(member):
    """The function behind a class member (classmethods and staticmethods unwrapped)."""
    return member.__func__ if isinstance(member, (classmethod, staticmethod)) else member


def public_callables():
    seen = set()
    for info in pkgutil.walk_packages(slamlab.__path__, "slamlab."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]):
            continue
        module = importlib.import_module(info.name)
        for attr, obj in sorted(vars(module).items()):
            if attr.startswith("_") or not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if getattr(obj, "__module__", None) != info.name:
                continue
            items = [(f"{info.name}.{attr}", obj)]
            if inspect.isclass(obj):
                items += [(f"{info.name}.{attr}.{a}", _function(v)) for a, v in vars(obj).items()
                          if not a.startswith("_") and inspect.isfunction(_function(v))]
            for qualname, o in items:
                if id(o) not in seen:
                    seen.add(id(o))
                    yield qualname, o


def parameter_names(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p for p in sig.parameters if p not in ("self", "cls")]


def missing_parameters(prefix: str = "slamlab.") -> dict[str, str]:
    problems = {}
    for qualname, obj in public_callables():
        if not qualname.startswith(prefix):
            continue
        params = parameter_names(obj)
        if not params:
            continue
        doc = inspect.getdoc(obj) or ""
        sections = ("Parameters", "Attributes") if inspect.isclass(obj) else ("Parameters",)
        names = documented_names(doc, sections)
        if names is None:
            problems[qualname] = "no Parameters section"
            continue
        absent = [p for p in params if p not in names]
        if absent:
            problems[qualname] = f"undocumented: {', '.join(absent)}"
    return problems


def test_the_checker_reads_numpydoc_sections():
    doc = ("Summary.\n\nParameters\n----------\nx, y : float\n    Coordinates.\n**overrides\n    Fields.\n"
           "    not_a_name : nested text\n\nReturns\n-------\nz : float\n    Sum.\n")
    assert documented_names(doc) == {"x", "y", "overrides"}
    assert documented_names("Summary only.") is None


def test_every_public_callable_documents_its_parameters():
    problems = missing_parameters()
    assert not problems, f"{len(problems)} public callables without a complete Parameters section:\n" + "\n".join(
        f"  {k}: {v}" for k, v in sorted(problems.items()))


if __name__ == "__main__":  # python tests/test_docstrings.py [prefix]  -> list per object
    import sys
    probs = missing_parameters(sys.argv[1] if len(sys.argv) > 1 else "slamlab.")
    for k, v in sorted(probs.items()):
        print(f"{k}: {v}")
    print(len(probs), "problems")
