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
from typing import Any, TypeVar

from ._table import format_table

__all__ = ["Params", "param"]

P = TypeVar("P", bound="Params")


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

    def table(self) -> str:
        """Every field, its value and its source, as a text table."""
        src = self.sources()
        rows = [[k, _fmt(getattr(self, k)), src[k]] for k in self.field_names()]
        return format_table(["parameter", "value", "source"], rows, title=type(self).__name__)


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return repr(value) if isinstance(value, str) else str(value)
