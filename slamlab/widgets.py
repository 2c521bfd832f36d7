"""Shared widget helpers for the chapters' ``explore_*`` functions (the one place for them).

Every chapter's ``<topic>/widgets.py`` builds its sliders with :func:`slider` (no
update while dragging), labels its controls with :data:`STYLE` (wide descriptions) and
runs each update through :func:`show_run` (the run, then its table, then its figure,
or one readable message instead of a traceback).
"""

from __future__ import annotations

__all__ = ["STYLE", "show_run", "slider"]

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
