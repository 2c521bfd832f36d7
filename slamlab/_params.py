"""Frozen parameter objects for the pipelines (CONVENTIONS: Settings).

A pipeline's knobs live in one frozen dataclass derived from :class:`Params`.
Every field is declared with :func:`param`, which records where its default comes
from (a source section such as ``"004 §3"`` or ``"ours"``); the subclass checks
every field in one method, :meth:`Params.check`, which runs once, when the object
is made. ``run_*`` functions take ``params=`` plus keyword overrides and call
:meth:`Params.resolve`::

    @dataclass(frozen=True)
    class MyParams(Params):
        H_min: int = param(15, "004 §5: a parameter, value not given")
        def check(self):
            v.check_int(self.H_min, "H_min", minimum=1)

    def run_thing(*, params=None, **overrides):
        p = MyParams.resolve(params, **overrides)

An override that names no field is a ``TypeError`` listing the fields, so a typo
never passes silently.
"""

from __future__ import annotations

import dataclasses
import textwrap
from collections.abc import Sequence
from typing import Any, TypeVar

from ._table import format_table

__all__ = ["Params", "param", "refuse_set_fields"]

P = TypeVar("P", bound="Params")

#: The widest line of :meth:`Params.table` (the output area of JupyterLab at its default width).
TABLE_WIDTH = 110
#: The widest value :meth:`Params.table` prints in its column (a longer one goes to a note).
_VALUE_ROOM = 32


def param(default: Any, source: str, **kwargs: Any) -> Any:
    """A field of a :class:`Params` dataclass with its default's ``source`` ("000 §3.5", "ours", ...).

    Mutable defaults are not allowed (the object is frozen and shared); use a tuple.
    """
    if not isinstance(source, str) or not source.strip():
        raise TypeError(f"`source` must be a non-empty string naming the source section or 'ours'; got {source!r}")
    if isinstance(default, (list, dict, set)):
        raise TypeError(f"a Params default must be immutable; got {type(default).__name__}")
    return dataclasses.field(default=default, metadata={"source": source}, **kwargs)


@dataclasses.dataclass(frozen=True)
class Params:
    """Base of every pipeline's frozen parameters; subclasses are frozen dataclasses too."""

    def __post_init__(self) -> None:
        self.check()

    def check(self) -> None:
        """Check every field; raise ``TypeError``/``ValueError`` naming the field. Subclasses override."""

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The names of the fields, in declaration order."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def sources(cls) -> dict[str, str]:
        """Field name → the source of its default (a section of the sources, or "ours")."""
        return {f.name: f.metadata.get("source", "ours") for f in dataclasses.fields(cls)}

    def replace(self: P, **overrides: Any) -> P:  # noqa: PYI019 (typing.Self needs 3.11)
        """A copy with some fields changed (checked again); unknown names are a ``TypeError``."""
        unknown = sorted(set(overrides) - set(self.field_names()))
        if unknown:
            raise TypeError(f"{type(self).__name__} has no field(s) {', '.join(map(repr, unknown))}; "
                            f"fields are: {', '.join(self.field_names())}")
        return dataclasses.replace(self, **overrides) if overrides else self

    @classmethod
    def resolve(cls: type[P], params: P | None = None, **overrides: Any) -> P:  # noqa: PYI019
        """``params`` (default: ``cls()``) with ``overrides`` applied: what every ``run_*`` calls once."""
        if params is None:
            base = cls()
        elif isinstance(params, cls):
            base = params
        else:
            raise TypeError(f"`params` must be a {cls.__name__} or None; got {type(params).__name__}")
        return base.replace(**overrides)

    @classmethod
    def as_overrides(cls, params: P | None = None, **overrides: Any) -> dict[str, Any]:
        """``params`` plus ``overrides`` as one dict of overrides of the defaults (checked by :meth:`resolve`).

        For a ``run_*`` that hands its settings to worker tasks as keyword overrides: the fields of
        ``params`` that differ from the defaults, then ``overrides`` (which win). With ``params=None`` the
        result is ``overrides`` unchanged, so a study called the old way runs exactly as before.

        Parameters
        ----------
        params : Params or None
            The base settings (an instance of ``cls``).
        **overrides
            Fields to change.

        Returns
        -------
        dict
            Field name → value; ``cls.resolve(None, **result) == cls.resolve(params, **overrides)``.
        """
        cls.resolve(params, **overrides)  # a bad `params` or override fails here, naming the fields
        return {**(params.changed() if params is not None else {}), **overrides}

    def changed(self) -> dict[str, Any]:
        """The fields whose value differs from the class default."""
        default = type(self)()
        return {k: getattr(self, k) for k in self.field_names() if getattr(self, k) != getattr(default, k)}

    def table(self, width: int = TABLE_WIDTH) -> str:
        """Every field, its value and its source, as a text table no line of which is wider than ``width``.

        A source (or a value) too long for its column is cut at a clause boundary and marked ``[n]``; the whole
        text is note ``[n]`` under the table, wrapped at ``width``.

        Parameters
        ----------
        width : int
            The widest line (default :data:`TABLE_WIDTH`, JupyterLab's output area).

        Returns
        -------
        str
        """
        src = self.sources()
        names = self.field_names()
        values = [_fmt(getattr(self, k)) for k in names]
        notes: list[str] = []

        def fit(text: str, room: int, what: str) -> str:
            if len(text) <= room:
                return text
            tag = f"[{len(notes) + 1}]"
            notes.append(f"{tag} {what}: {text}")
            head = _head(text, room - len(tag) - 1)
            return f"{head} {tag}" if head else tag

        name_w = max(len("parameter"), *map(len, names))
        value_room = max(len("value"), min(max(map(len, values)), _VALUE_ROOM))
        rows = [[k, fit(v, value_room, f"{k} value") if len(v) > value_room else v] for k, v in zip(names, values, strict=True)]
        value_w = max(len("value"), *(len(r[1]) for r in rows))
        room = max(len("source"), width - name_w - value_w - 4)
        rows = [[k, v, fit(src[k], room, k)] for k, v in rows]
        out = format_table(["parameter", "value", "source"], rows, title=type(self).__name__)
        if notes:
            out += "\n" + "\n".join(textwrap.fill(n, width, subsequent_indent="    ", break_on_hyphens=False)
                                     for n in notes)
        return out


def refuse_set_fields(params: Params, names: Sequence[str], how: str, *, default: Params | None = None) -> None:
    """Refuse settings that change a field a study varies itself (ours: one route per setting).

    A study whose grid runs over fields of its settings object (particle counts, the two arms of an ablation)
    sets them itself; the settings the caller gave (``params`` with the overrides applied) must leave them at
    their class defaults, else a ``ValueError`` names the fields and says how the study sets them, so a value is
    never silently replaced.

    Parameters
    ----------
    params : Params
        The caller's settings (a frozen ``Params`` dataclass, e.g. :class:`~slamlab.localisation.MCLParams`).
    names : sequence of str
        The fields the study varies itself.
    how : str
        How the study sets them (e.g. "one run per count of `particle_counts`").
    default : Params, optional
        The settings the study starts from, which ``params`` must leave the fields at (default: the class
        defaults).

    Returns
    -------
    None

    Raises
    ------
    ValueError
        Naming every field in ``names`` that the settings change, with ``how`` and the defaults.

    Examples
    --------
    >>> from slamlab.localisation import MCLParams
    >>> refuse_set_fields(MCLParams(sigma_hit=3.0), ["n_particles"], "one run per count")
    >>> refuse_set_fields(MCLParams(n_particles=50), ["n_particles"], "one run per count")
    Traceback (most recent call last):
    ...
    ValueError: `n_particles` is set by this study itself (one run per count); `params` or an override sets it to 50 (leave the default 2000)
    """
    default = type(params)() if default is None else default
    clash = [(n, getattr(params, n), getattr(default, n)) for n in names if getattr(params, n) != getattr(default, n)]
    if clash:
        fields = ", ".join(f"`{n}`" for n, _, _ in clash)
        values = ", ".join(repr(v) for _, v, _ in clash)
        defaults = ", ".join(repr(d) for _, _, d in clash)
        verb = "is" if len(clash) == 1 else "are"
        raise ValueError(f"{fields} {verb} set by this study itself ({how}); `params` or an override sets "
                         f"{'it' if len(clash) == 1 else 'them'} to {values} (leave the default {defaults})")


def _head(text: str, room: int) -> str:
    """The longest start of ``text`` that ends at a clause boundary outside brackets and fits in ``room``."""
    best, depth = "", 0
    for i, ch in enumerate(text):
        if ch in "([":
            if depth == 0 and i <= room and text[i - 1:i] == " ":
                best = text[:i - 1]
            depth += 1
        elif ch in ")]":
            depth = max(0, depth - 1)
        elif depth == 0 and ch in ";:," and i <= room:
            best = text[:i]
        if i > room:
            break
    return best.rstrip()


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, tuple) and value and all(isinstance(x, (int, float)) for x in value):
        return f"({', '.join(_fmt(x) for x in value)}{',' if len(value) == 1 else ''})"
    return repr(value) if isinstance(value, str) else str(value)
