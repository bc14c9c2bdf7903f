"""Mode-shape figures: the shapes of one state with the structure marked (steps, springs, masses, stops)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from .figure import PlotHandles, _finish, _new_figure

_MM = 1e3

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..modal import ModeSet

__all__ = ["plot_modes"]


def plot_modes(
    modes: ModeSet,
    *,
    count: int | None = 6,
    contactors: Sequence[Any] = (),
    ax: Axes | None = None,
    title: str | None = None,
    path: str | os.PathLike[str] | None = None,
    dpi: int = 110,
) -> PlotHandles:
    """Mode shapes of one state, each scaled to a largest deflection of 1, with the structure marked.

    Section steps are dotted vertical lines (artist ``"steps"``), permanent
    springs triangles (``"springs"``), point masses squares (``"masses"``),
    engaged contact springs and the given ``contactors`` crosses
    (``"contactors"``). Rigid-body modes are drawn too (straight lines).

    Parameters
    ----------
    modes : ModeSet
        From :func:`impactbeam.mode_set` or ``ib.modes(scenario).free``.
    count : int or None
        How many modes to draw (the first ones); None: all.
    contactors : sequence of Contactor
        Contactors of the scenario (drawn at their positions).
    ax : matplotlib Axes, optional
        Draw here instead of on a new figure.
    title : str, optional
    path : str or path-like, optional
        Also save the figure there (:func:`impactbeam.plot.save_figure`).
    dpi : int
        Resolution of raster formats.

    Returns
    -------
    PlotHandles
    """
    if ax is None:
        fig, grid = _new_figure((7.5, 4.0))
        ax = grid[0, 0]
    else:
        fig = ax.figure
    beam = modes.beam
    L = beam.length
    x = np.union1d(np.linspace(0.0, L, 801), modes.nodes)
    n = modes.count if count is None else min(int(count), modes.count)
    W = modes.shapes(x)[:n]
    lines = []
    for i in range(n):
        peak = np.abs(W[i]).max()
        w = W[i] / peak if peak > 0 else W[i]
        label = f"{i + 1}: {modes.frequencies_hz[i]:.4g} Hz" if modes.omega[i] > 0 else f"{i + 1}: rigid"
        lines.extend(ax.plot(x * _MM, w, color=f"C{i % 10}", label=label))
    artists: dict[str, Any] = {}
    steps = np.cumsum([p.length for p in beam.pieces()])[:-1]
    artists["steps"] = [ax.axvline(s * _MM, color="0.4", ls=":", lw=1.0) for s in steps]
    sp = [s.position for s in beam.springs]
    artists["springs"] = ax.plot(np.asarray(sp) * _MM, np.full(len(sp), -1.08), ls="none", marker="^",
                                 color="k", ms=8, label="spring" if sp else None)[0]
    mx = [m.position for m in beam.masses]
    artists["masses"] = ax.plot(np.asarray(mx) * _MM, np.zeros(len(mx)), ls="none", marker="s", color="k",
                                ms=9, mfc="0.7", label="point mass" if mx else None)[0]
    cx = sorted({float(c.position) for c in contactors} | {float(p) for p, _ in modes.springs})
    artists["contactors"] = ax.plot(np.asarray(cx) * _MM, np.full(len(cx), 1.08), ls="none", marker="x",
                                    color="C3", ms=8, label="contactor" if cx else None)[0]
    ax.axhline(0.0, color="0.7", lw=0.8)
    ax.set_xlim(0.0, L * _MM)
    ax.set_ylim(-1.2, 1.2)
    ax.set_xlabel("position x [mm]")
    ax.set_ylabel("mode shape W / max|W| [-]")
    if title:
        ax.set_title(title)
    artists["legend"] = ax.legend(fontsize=7, ncols=2, loc="upper left")
    return _finish(PlotHandles(fig, (ax,), tuple(lines), artists), path, dpi)
