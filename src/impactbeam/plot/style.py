"""Journal style of the figures of :mod:`impactbeam.plot`: sizes, fonts, series styles."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .._optional import require
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["SERIES_STYLES", "STYLE", "WIDTHS", "figure_size", "surface_w"]

_G = 9.80665

#: Figure widths [in]: one and two journal columns.
WIDTHS = {"single": 3.5, "double": 7.0}

#: (colour, line style, marker) of successive series: Okabe-Ito colours and
#: distinct dash patterns, distinguishable in grey-scale and by colour-blind readers.
SERIES_STYLES: tuple[tuple[str, Any, str], ...] = (
    ("#000000", "-", "o"),
    ("#0072B2", "--", "s"),
    ("#D55E00", ":", "^"),
    ("#009E73", "-.", "D"),
    ("#CC79A7", (0, (5, 1.5, 1, 1.5, 1, 1.5)), "v"),
    ("#E69F00", (0, (8, 2)), "P"),
    ("#56B4E9", (0, (1, 1)), "X"),
)

#: Matplotlib settings of every figure drawn here (fonts >= 8 pt at print size).
STYLE = {
    "font.size": 8,
    "axes.labelsize": 8,
    "axes.titlesize": 9,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "legend.fontsize": 8,
    "lines.linewidth": 1.0,
    "axes.linewidth": 0.6,
    "grid.linewidth": 0.4,
    "savefig.dpi": 300,
}

_EXCITATION_AXIS = {
    "base_acceleration": ("base acceleration [g]", 1 / _G),
    "point_force": ("force [N]", 1.0),
    "distributed_force": ("distributed force [N/m]", 1.0),
}


def figure_size(size: str | tuple[float, float] = "double", aspect: float = 0.5) -> tuple[float, float]:
    """Width and height [in] of a figure: ``"single"`` (3.5 in) or ``"double"`` column (7 in).

    Parameters
    ----------
    size : "single", "double" or (width, height)
        A journal column width, or an explicit size in inches (passed through).
    aspect : float
        Height / width for a column width.

    Returns
    -------
    (width, height) : tuple of float, [in]
    """
    if isinstance(size, tuple):
        return size
    if size not in WIDTHS:
        raise ParameterError(f'size: must be "single", "double" or (width, height) in inches, got {size!r}')
    return WIDTHS[size], WIDTHS[size] * aspect


def surface_w(contactor: Any) -> float:
    """The deflection ``w`` [m] of a contactor's surface: ``+gap`` above the beam, ``-gap`` below.

    Parameters
    ----------
    contactor : Contactor
        Its ``gap`` and ``direction`` (+1 above, -1 below).
    """
    return float(contactor.direction * contactor.gap)


def _style(i: int) -> dict[str, Any]:
    color, ls, _ = SERIES_STYLES[i % len(SERIES_STYLES)]
    return {"color": color, "ls": ls}


def _styled(fn: Any) -> Any:
    """Run a plotting function under :data:`STYLE` (an rc context, restored afterwards)."""
    import functools

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        mpl = require("matplotlib", "plot")
        with mpl.rc_context(STYLE):
            return fn(*args, **kwargs)

    return wrapper


def _outside_legend(fig: Figure, ax: Axes, ncols: int = 3) -> Any:
    """A legend below the axes grid (never over the data); None when nothing is labelled."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    # about 14 characters of 8 pt text per inch, plus the line sample: columns that fit the width
    fit = int(fig.get_figwidth() * 14 // (max(len(str(lab)) for lab in labels) + 7))
    ncols = max(1, min(ncols, len(handles), fit))
    return fig.legend(handles, labels, loc="outside lower center", ncols=ncols, frameon=False)


def _side_legend(ax: Axes) -> Any:
    """A legend to the right of given axes (outside the data); None when nothing is labelled."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, frameon=False)


def _wrap(label: str, width: int = 38) -> str:
    """Break a long axis label into lines so that it fits a narrow panel."""
    import textwrap

    return "\n".join(textwrap.wrap(label, width)) if len(label) > width else label


def _log_ticks(axis: Any) -> None:
    """Label a log axis at 1, 2, 5 times the decades only, in plain numbers (no overlap)."""
    ticker = require("matplotlib.ticker", "plot")
    axis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0), numticks=12))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_locator(ticker.LogLocator(base=10, subs=np.arange(1, 10) * 1.0, numticks=12))
    axis.set_minor_formatter(ticker.NullFormatter())


#: SI unit -> (display unit, factor) for axes: lengths in mm and times in ms, as the summaries.
DISPLAY_UNITS = {"m": ("mm", 1e3), "s": ("ms", 1e3)}


def display_label(name: str, units: str | None) -> tuple[str, float]:
    """Axis label and scale factor of a labelled quantity, e.g. ``"contactors.0.gap", "m"`` ->
    ``("gap [mm]", 1000.0)``; the first contactor's index is dropped, others are kept.
    """
    parts = name.split(".")
    short = parts[-1].replace("_", " ")
    if len(parts) == 3 and parts[0] == "contactors" and parts[1] != "0":
        short += f" (contactor {parts[1]})"
    elif len(parts) == 2 and parts[0] == "excitation" and parts[1] in ("duration", "start"):
        short = f"pulse {short}"
    elif len(parts) == 2 and parts[0] == "excitation" and parts[1] in ("amplitude", "scale"):
        short = f"load {short}"  # a pulse's or a harmonic load's
    elif len(parts) == 2 and parts[0] == "excitation" and parts[1] in ("frequency", "phase"):
        short = f"forcing {short}"
    elif len(parts) == 2 and parts[0] == "damping":
        short = f"damping ratio, {parts[1]} state"
    unit, scale = DISPLAY_UNITS.get(units or "", (units, 1.0))
    return (f"{short} [{unit}]" if unit not in (None, "", "1") else short), scale


def rc_context() -> Any:
    """The rc context of :data:`STYLE`, for figures assembled from several calls."""
    return require("matplotlib", "plot").rc_context(STYLE)


def _response_label(runs: list[Any], quantity: str, side: str) -> str:
    if quantity == "w":
        return "deflection w [mm]"
    if all(len(r.contactors) for r in runs):
        return "distance from contactor surface d [mm]\n(positive away; < 0: in contact)"
    if not any(len(r.contactors) for r in runs):
        return f"deflection {'-w' if side == 'above' else 'w'} [mm]"
    return "d (runs with contactor), u (without) [mm]"
