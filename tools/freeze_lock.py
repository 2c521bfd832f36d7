#!/usr/bin/env python
"""Print ``constraints.txt``: the exact version of every installed distribution.

Run by ``make lock`` with the python of a fresh venv that has just installed
``-e '.[test]'``. Like ``pip freeze`` (slamlab itself and pip/setuptools/wheel left
out), except that a pin whose release needs a newer Python than 3.10 carries an
environment marker with that release's ``Requires-Python``, so that the same lock
installs on Python 3.10 (those packages then resolve freely within pyproject's
bounds) and pins everything on the Python the lock was made with.
"""

from __future__ import annotations

import platform
import sys
from importlib.metadata import distributions

from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name

SKIP = {"slamlab", "pip", "setuptools", "wheel", "distribute"}
OLDEST_SUPPORTED = "3.10"


def lock_lines() -> list[str]:
    pins: dict[str, str] = {}
    for dist in distributions():
        name = canonicalize_name(dist.metadata["Name"])
        if name in SKIP:
            continue
        line = f"{name}=={dist.version}"
        requires = dist.metadata.get("Requires-Python")
        if requires:
            spec = SpecifierSet(requires)
            if not spec.contains(OLDEST_SUPPORTED + ".0"):
                marker = " and ".join(f'python_full_version {s.operator} "{s.version}"' for s in spec)
                line += f"; {marker}"
        pins[name] = line
    return [pins[name] for name in sorted(pins)]


def main() -> None:
    version = platform.python_version()
    print("# Exact versions of every package slamlab[test] installs; made by `make lock` (tools/freeze_lock.py)")
    print(f"# in a fresh venv on Python {version}, {sys.platform} {platform.machine()}. `make venv` installs with")
    print("# pip -c constraints.txt. Pins whose release needs Python > 3.10 carry that Requires-Python as a marker.")
    for line in lock_lines():
        print(line)


if __name__ == "__main__":
    main()
