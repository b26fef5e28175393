"""What every figure shares: new figures that leave the user's backend alone, axes given or
made, and an atomic save.

A drawing function takes an optional ``ax`` (one Axes, or a sequence of them for a
figure of several panels) and returns the Figure it drew on. Without ``ax`` it makes a
figure through pyplot, so that it shows as any matplotlib figure does (in a window on a
desktop backend, in the gallery's scraper). Jupyter's inline backend is the exception:
it shows every pyplot figure at the end of a cell, and the returned Figure shows again
as the cell's value, so there the new figure is closed in pyplot at once and shows once,
as the value (or with ``display(fig)``). Figures written to files are made inside
:func:`offscreen` instead: plain :class:`matplotlib.figure.Figure` objects that no
backend, window or pyplot list knows, so saving one neither needs a display nor
changes the backend (the CLI draws this way).
"""

from __future__ import annotations

import contextvars
from collections.abc import Sequence
from contextlib import contextmanager
from pathlib import Path

from ..io.files import atomic_path

_OFFSCREEN = contextvars.ContextVar("beltsim_offscreen", default=False)


@contextmanager
def offscreen():
    """Make the figures drawn inside plain Figures, unknown to pyplot (for files).

    Examples
    --------
    >>> with offscreen():                                          # doctest: +SKIP
    ...     fig = plot_fields(result)
    >>> fig.savefig("fields.png")                                  # doctest: +SKIP
    """
    token = _OFFSCREEN.set(True)
    try:
        yield
    finally:
        _OFFSCREEN.reset(token)


def new_figure(figsize, **kwargs):
    """A new figure: pyplot's, or inside :func:`offscreen` a plain one.

    Parameters
    ----------
    figsize : (float, float)
        Width and height in inches.
    **kwargs
        Passed to the Figure (e.g. ``layout="constrained"``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    if _OFFSCREEN.get():
        from matplotlib.figure import Figure
        return Figure(figsize=figsize, **kwargs)
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=figsize, **kwargs)
    if _inline_backend():
        # the inline backend would show it at the cell's end, and the returned Figure
        # again as the cell's value; closed, it still draws and saves, and shows once
        plt.close(fig)
    return fig


def _inline_backend() -> bool:
    """Whether pyplot draws through Jupyter's inline backend (matplotlib-inline)."""
    import matplotlib

    backend = str(matplotlib.get_backend()).lower()
    return backend == "inline" or backend.endswith("backend_inline")


def panel_axes(ax, nrows: int, ncols: int = 1, figsize=(8.0, 6.0), **kwargs):
    """The axes a drawing function draws its ``nrows`` x ``ncols`` panels on.

    Parameters
    ----------
    ax : Axes, sequence of Axes, or None
        The caller's: one Axes for a single panel, else one per panel (any shape,
        read row by row). None makes a new figure (:func:`new_figure`).
    nrows, ncols : int
        The panels of a new figure.
    figsize : (float, float)
        A new figure's size in inches.
    **kwargs
        Passed to ``Figure.subplots`` for a new figure (e.g. ``sharex=True``).

    Returns
    -------
    fig : matplotlib.figure.Figure
        The figure the axes belong to.
    axes : list of Axes
        One per panel, row by row.
    own : bool
        True for a new figure (the caller may dress it: title, legend).

    Raises
    ------
    ValueError
        ``ax`` holds another number of Axes than there are panels.
    """
    n = nrows * ncols
    if ax is None:
        fig = new_figure(figsize, layout="constrained")
        axes = fig.subplots(nrows, ncols, squeeze=False, **kwargs)
        return fig, list(axes.ravel()), True
    if isinstance(ax, Sequence) or hasattr(ax, "ravel"):
        axes = list(ax.ravel()) if hasattr(ax, "ravel") else [a for a in ax]
    else:
        axes = [ax]
    if len(axes) != n:
        raise ValueError(f"ax: this figure has {n} panel{'s' if n > 1 else ''}, got "
                         f"{len(axes)} Axes (pass {'one Axes' if n == 1 else f'{n} Axes'} or "
                         f"none)")
    return axes[0].figure, axes, False


def save(fig, path, dpi) -> Path:
    """Save a figure through a temporary file and a rename.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or Path
        The file; its suffix gives the format.
    dpi : float

    Returns
    -------
    Path
    """
    path = Path(path)
    with atomic_path(path, suffix=path.suffix) as tmp:
        fig.savefig(tmp, dpi=dpi)
    return path


def save_figure(draw, path, *args, dpi=110, **kwargs) -> Path:
    """Draw a figure off screen with ``draw(*args, **kwargs)`` and save it to ``path``.

    Parameters
    ----------
    draw : callable
        A drawing function that returns its Figure (e.g. :func:`~beltsim.plot_fields`).
    path : str or Path
        The file (written atomically).
    *args, **kwargs
        Passed to ``draw``.
    dpi : float, optional

    Returns
    -------
    Path

    Examples
    --------
    >>> save_figure(plot_history, "history.png", result)          # doctest: +SKIP
    """
    with offscreen():
        fig = draw(*args, **kwargs)
    return save(fig, path, dpi)
