"""Shared widget helpers for the chapters' ``explore_*`` functions (the one place for them).

Every chapter's ``<topic>/widgets.py`` builds its sliders with :func:`slider` (no
update while dragging) and labels its controls with :data:`STYLE` (wide descriptions).
"""

from __future__ import annotations

__all__ = ["STYLE", "slider"]

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

