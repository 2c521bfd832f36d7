"""Shared widget helpers for the chapters' ``explore_*`` functions (the one place for them).

Every chapter's ``<topic>/widgets.py`` builds its sliders with :func:`slider` (no
update while dragging), labels its controls with :data:`STYLE` (wide descriptions) and
runs each update through :func:`show_run` (the run, then its table, then its figure,
or one readable message instead of a traceback), and returns :func:`interactive`, whose
text form (what a notebook stores beside the widget) is one short line.
"""

from __future__ import annotations

import functools

__all__ = ["STYLE", "interactive", "show_run", "slider"]

#: Label style shared by every control: wide descriptions are not cut off.
STYLE = {"description_width": "initial"}


def slider(cls, value, lo, hi, step, desc: str, **kw):
    """An ipywidgets slider of class ``cls`` that updates on release only.

    Parameters
    ----------
    cls : type
        The ipywidgets slider class (``FloatSlider``, ``IntSlider``, ...).
    value, lo, hi, step : float or int
        Initial value, minimum, maximum and step.
    desc : str
        The slider's label.
    **kw
        Further keyword arguments for ``cls``.

    Returns
    -------
    slider : ipywidgets.Widget
        The slider with ``continuous_update=False`` and the shared label style.

    Examples
    --------
    >>> import ipywidgets as widgets
    >>> s = slider(widgets.FloatSlider, 0.5, 0.0, 1.0, 0.1, "noise")
    >>> s.continuous_update, s.description
    (False, 'noise')
    """
    return cls(value=value, min=lo, max=hi, step=step, description=desc, continuous_update=False, style=STYLE, **kw)


@functools.cache
def _interactive_class():
    import ipywidgets

    class Interactive(ipywidgets.interactive):
        """``ipywidgets.interactive`` whose text form names the explore function and counts its controls."""

        def __repr__(self) -> str:
            parts = getattr(self.f, "__qualname__", "widget").split(".<locals>.")
            name = parts[-2] if len(parts) > 1 else parts[0]  # the function that built the widget
            n = len(self.kwargs_widgets)
            text = f"{name}: {n} control{'' if n == 1 else 's'}"
            return f"{text} (ipywidgets)" if len(text) <= 47 else text[:60]

    return Interactive


def interactive(show, options=None, /, **controls):
    """``ipywidgets.interactive(show, options, **controls)`` with a one-line text form.

    ipywidgets' own text form spells out the first controls and their settings and
    cuts it at 110 characters, so a notebook stores a line too wide for JupyterLab's
    output area. This one names the ``explore_*`` function and counts the controls,
    in at most 60 characters. Everything else is ``ipywidgets.interactive``.

    Parameters
    ----------
    show : callable
        The update function; it receives the controls' values by keyword.
    options : dict, optional
        ipywidgets' options of the interaction, e.g. ``{"manual": True, "manual_name": "run"}`` for a run
        button instead of an update on every change.
    **controls
        The controls (widgets or ipywidgets abbreviations), one per argument of ``show``.

    Returns
    -------
    ipywidgets.interactive
        The widget (an instance of a subclass that only changes ``repr``).

    Examples
    --------
    >>> import ipywidgets as widgets
    >>> def explore_noise(**defaults):
    ...     def show(noise, n):
    ...         pass
    ...     return interactive(show, noise=slider(widgets.FloatSlider, 0.5, 0.0, 1.0, 0.1, "noise"),
    ...                        n=slider(widgets.IntSlider, 3, 1, 9, 1, "n"))
    >>> import contextlib, io
    >>> with contextlib.redirect_stdout(io.StringIO()):  # the first update clears the (terminal) output
    ...     w = explore_noise()
    >>> isinstance(w, widgets.interactive), repr(w)
    (True, 'explore_noise: 2 controls (ipywidgets)')
    >>> w._repr_mimebundle_()["text/plain"]
    'explore_noise: 2 controls (ipywidgets)'
    """
    return _interactive_class()(show, {} if options is None else dict(options), **controls)


def show_run(run, draw=None, *, table=None, errors=(ValueError, TypeError)):
    """One update of an ``explore_*`` widget: the run, then its table, then its figure.

    Calls ``run()``. If it raises one of ``errors``, prints
    ``Cannot run with these settings: <message>`` and stops there: no table, no
    figure, no traceback in the widget's output area. Otherwise prints
    ``table(result)`` and then calls ``draw(result)``. Only ``run()`` is guarded:
    an error in ``table`` or ``draw`` is a bug and propagates.

    Parameters
    ----------
    run : callable
        ``run() -> result``: the experiment with the controls' values bound.
    draw : callable, optional
        ``draw(result)``: plots the result; None draws nothing.
    table : callable, optional
        ``table(result) -> str``: the text printed before drawing; default
        ``result.table()``.
    errors : tuple of type, optional
        The exceptions a bad combination of settings raises (default
        ``(ValueError, TypeError)``); a widget that reads data files adds
        ``FileNotFoundError``.

    Returns
    -------
    None
        Nothing, so that ``ipywidgets.interactive`` displays no return value.

    Examples
    --------
    >>> def run(n):
    ...     if n < 1:
    ...         raise ValueError(f"`n` must be >= 1; got {n}")
    ...     return n
    >>> show_run(lambda: run(0), print)
    Cannot run with these settings: `n` must be >= 1; got 0
    >>> show_run(lambda: run(2), lambda n: print("drawn", n), table=lambda n: f"n = {n}")
    n = 2
    drawn 2
    """
    try:
        result = run()
    except errors as exc:
        print(f"Cannot run with these settings: {exc}")
        return
    print(result.table() if table is None else table(result))
    if draw is not None:
        draw(result)
