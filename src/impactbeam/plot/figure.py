"""Figures as objects: what a plotting function drew, and writing it to a file.

Every figure of the package is a bare :class:`matplotlib.figure.Figure` on the
Agg canvas (never pyplot's global state, whatever the user's backend), wrapped
in :class:`PlotHandles`, which Jupyter displays as the figure, and written
atomically by :func:`save_figure` in the format of the file's suffix.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._io import PLOT_SUFFIXES, atomic_path
from .._optional import require
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["PlotHandles", "save_figure", "FIGURE_SUFFIXES"]

#: Image formats :func:`save_figure` accepts (by file suffix).
FIGURE_SUFFIXES = PLOT_SUFFIXES

@dataclass(frozen=True)
class PlotHandles:
    """What a plotting function drew.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    axes : tuple of Axes
        Every axes drawn on, main axes first.
    lines : tuple of Line2D
        The data lines, in drawing order.
    artists : dict
        Other named artists (``"contact_spans"``, ``"impacts"``, ``"legend"`` ...).
    """

    figure: Figure
    axes: tuple[Axes, ...]
    lines: tuple[Any, ...]
    artists: dict[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        return f"<PlotHandles: figure with {len(self.axes)} axes, {len(self.lines)} lines>"

    def _repr_mimebundle_(self, include: Any = None, exclude: Any = None) -> dict[str, Any]:
        """Jupyter shows the figure (PNG), not a text dump."""
        import io

        buf = io.BytesIO()
        self.figure.savefig(buf, format="png", dpi=150)
        return {"image/png": buf.getvalue(), "text/plain": repr(self)}

    def save(self, path: str | os.PathLike[str], *, dpi: int = 300) -> Path:
        """Write the figure to ``path`` (format from the suffix); see :func:`save_figure`.

        Parameters
        ----------
        path : str or path-like
            The file; its suffix chooses the format (:data:`FIGURE_SUFFIXES`).
        dpi : int
            Resolution of raster formats.

        Returns
        -------
        Path
        """
        return save_figure(self.figure, path, dpi=dpi)


def _new_figure(figsize: tuple[float, float], nrows: int = 1, ncols: int = 1, **kw: Any) -> tuple[Figure, Any]:
    """A figure on the Agg canvas, independent of pyplot's global state."""
    FigureCanvasAgg = require("matplotlib.backends.backend_agg", "plot").FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes


def save_figure(figure: Figure, path: str | os.PathLike[str], *, dpi: int = 300, **savefig: Any) -> Path:
    """Write ``figure`` to ``path`` atomically (temporary file + :func:`os.replace`).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
    path : str or path-like
        The file; its suffix chooses the format (:data:`FIGURE_SUFFIXES`).
    dpi : int
        Resolution of raster formats; ``.pdf``, ``.svg`` and ``.eps`` are vector.
    **savefig
        More options of :meth:`matplotlib.figure.Figure.savefig` (e.g. ``bbox_inches``).

    Returns
    -------
    Path

    Raises
    ------
    ParameterError
        The suffix is not an image format matplotlib writes.
    OSError
        The directory does not exist or is not writable.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in FIGURE_SUFFIXES:
        raise ParameterError(f'figure path: unsupported file type "{p.suffix or p.name}" (use {", ".join(FIGURE_SUFFIXES)})')
    with atomic_path(p) as tmp:
        meta = {".png": {"Software": None}, ".pdf": {"CreationDate": None}, ".svg": {"Date": None}}.get(suffix)
        figure.savefig(tmp, format=suffix.lstrip("."), dpi=dpi, metadata=meta, **savefig)
    return p


def _finish(handles: PlotHandles, path: str | os.PathLike[str] | None, dpi: int = 300) -> PlotHandles:
    if path is not None:
        save_figure(handles.figure, path, dpi=dpi)
    return handles
