"""Plots: functions take data (and, for one panel, an optional Axes) and return the Figure; axis
labels carry units. Importing this module selects matplotlib's Agg backend.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from reference.results.summary import Status  # noqa: E402

__all__ = ["CLASS_COLOURS", "speed_ratio", "data_limits", "efficiency_against_input_angle", "pair_losses",
           "efficiency_against_paper", "save", "close", "stability_map"]


def _axes(ax):
    """``ax``'s figure and ``ax``, or a new figure with one Axes."""
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4.2), constrained_layout=True)
        return fig, ax
    return ax.figure, ax


def _against_input_angle(tables: dict[str, object], values, ylabel: str, ax=None):
    """``values(table)`` against the input angle [deg] modulo 360, one series per table."""
    fig, ax = _axes(ax)
    for label, t in tables.items():
        ax.plot(np.degrees(t["theta_in"]) % 360, values(t), ".", ms=1.5, label=label)
    ax.set_xlabel("input angle [deg]")
    ax.set_ylabel(ylabel)
    ax.set_xlim(0, 360)
    ax.legend(fontsize=7, ncol=2, markerscale=6)
    ax.grid(alpha=0.3)
    return fig


def speed_ratio(tables: dict[str, object], ax=None):
    """omega_out / omega_in against the input angle, one series per label of ``tables`` (time tables
    with ``theta_in`` [rad], ``omega_in``, ``omega_out`` [rad/s]), on ``ax`` or a new figure.
    """
    return _against_input_angle(tables, lambda t: t["omega_out"] / t["omega_in"],
                                "omega_out / omega_in [-]", ax)


def data_limits(values, margin: float = 0.08, min_span: float = 2e-3,
                clip: tuple[float, float] | None = None) -> tuple[float, float]:
    """Axis limits (values' unit) showing the finite ``values``: their range widened by ``margin`` [-]
    of its span each side, at least ``min_span`` wide (centred), then cut to ``clip``; none finite:
    ``clip`` or (0, 1).
    """
    x = np.asarray(values, dtype=float).ravel()
    x = x[np.isfinite(x)]
    if clip is not None:
        x = x[(x >= clip[0]) & (x <= clip[1])]
    if x.size == 0:
        return tuple(clip) if clip is not None else (0.0, 1.0)
    low = float(x.min())
    high = float(x.max())
    if high - low < min_span:  # centred on the values, so that a constant reads as one
        mid = 0.5 * (low + high)
        low = mid - 0.5 * min_span
        high = mid + 0.5 * min_span
    pad = margin * (high - low)
    low -= pad
    high += pad
    if clip is not None:
        low = max(low, clip[0])
        high = min(high, clip[1])
    return low, high


def efficiency_against_input_angle(curves: dict[str, tuple], title: str = "", ax=None,
                                   clip: tuple[float, float] = (-0.5, 1.05)):
    """Instantaneous efficiency of eq. (18) against the input angle (Figures 4, 6, 7 of the paper).

    Parameters
    ----------
    curves : dict of str to (array_like, array_like)
        Label -> (input angle [deg], efficiency [-]), one revolution each.
    title : str
        Panel title (none when empty).
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    clip : tuple of float
        Limits the y axis never leaves [-] (eq. (18) is unbounded where the input power changes sign).
    """
    fig, ax = _axes(ax)
    for label, (angle, eta) in curves.items():
        ax.plot(angle, eta, lw=0.9, label=label)
    ax.set_xlabel("input angle [deg]")
    ax.set_ylabel("instantaneous efficiency, eq. (18) [-]")
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 45))
    ax.set_ylim(*data_limits(np.concatenate([np.asarray(e, float) for _, e in curves.values()]),
                             clip=clip))
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9)
    return fig


def pair_losses(angle, losses: dict[str, object], title: str = ""):
    """Power loss [W] of the spider pairs (left) and shaft-frame pairs (right) against ``angle`` [deg]
    (the paper's Figure 5); ``losses``: pair name -> loss at ``angle``; ``title``: none when empty.
    """
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for ax, pairs in zip(axes, (("input_spider", "spider_output"), ("frame_input", "output_frame")),
                         strict=True):
        for pair in pairs:
            ax.plot(angle, losses[pair], lw=0.9, label=pair)
        ax.set_xlabel("input angle [deg]")
        ax.set_ylabel("power loss [W]")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 90))
        ax.set_ylim(*data_limits(np.concatenate([np.asarray(losses[p], float) for p in pairs]),
                                 min_span=1e-2))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=9)
    return fig


def efficiency_against_paper(panels: dict[str, object], x: str, xlabel: str):
    """Mean efficiency against the paper, one panel per parameter set.

    Lines: the set's mean efficiency (``o-``) and time average of eq. (18) (``x:``); markers: the
    paper's values (fitted cases filled, held-out open).

    Parameters
    ----------
    panels : dict of str to DataFrame
        Parameter set -> rows with ``x``, ``mean_efficiency``, ``mean_instantaneous_efficiency``,
        ``paper_mean_efficiency`` [-] and ``used_in_fit``.
    x, xlabel : str
        The abscissa's column, and its label with unit.
    """
    fig, axes = plt.subplots(1, len(panels), figsize=(4.4 * len(panels), 4), squeeze=False,
                             constrained_layout=True)
    for ax, (label, df) in zip(axes[0], panels.items(), strict=True):
        ax.plot(df[x], df["mean_efficiency"], "o-", ms=4, label="model: 1 - W_loss / W_in")
        ax.plot(df[x], df["mean_instantaneous_efficiency"], "x:", label="model: time average of eq. (18)")
        fit = df["used_in_fit"].astype(bool)
        ax.plot(df[x][fit], df["paper_mean_efficiency"][fit], "ks", ms=6, label="paper (fitted)")
        ax.plot(df[x][~fit], df["paper_mean_efficiency"][~fit], "ks", mfc="none", ms=6,
                label="paper (held out)")
        ax.set_ylim(*data_limits(np.concatenate([df[c].to_numpy(float) for c in (
            "mean_efficiency", "mean_instantaneous_efficiency", "paper_mean_efficiency")]),
            clip=(-0.05, 1.05)))
        ax.set_xlabel(xlabel)
        ax.set_ylabel("mean efficiency [-]")
        ax.set_title(label, fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6)
    return fig


def save(fig, path, dpi: int = 130) -> None:
    """Write ``fig`` to ``path`` (suffix sets the format; ``dpi`` for raster) and close it."""
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def close(fig) -> None:
    """Close ``fig`` (release its memory)."""
    plt.close(fig)


CLASS_COLOURS = {"converged": "#4caf50", "drift": "#ff9800", "self_locking": "#5c8fd6",
                 "integration_failure": "#e53935", "error": "#212121"}
"""Colour of each class of the stress map's cells."""


def _boundary(ax, locks: np.ndarray) -> None:
    """Black lines between cells of different reference state (``locks``, shape (angles, values))."""
    rows, cols = locks.shape
    for i in range(rows):
        for j in range(cols):
            if j + 1 < cols and locks[i, j] != locks[i, j + 1]:
                ax.plot([j + 0.5, j + 0.5], [i - 0.5, i + 0.5], "k", lw=2)
            if i + 1 < rows and locks[i, j] != locks[i + 1, j]:
                ax.plot([j - 0.5, j + 0.5], [i + 0.5, i + 0.5], "k", lw=2)


def _stability_panel(ax, sel, panel: dict, index: dict[str, int], cmap, classes) -> None:
    """One panel of :func:`stability_map`: the cells ``sel`` of ``panel``."""
    from matplotlib.patches import Rectangle

    xs = list(panel["x_values"])
    angles = list(panel["angles"])
    grid = np.full((len(angles), len(xs)), np.nan)
    locks = np.zeros_like(grid, dtype=bool)
    for _, r in sel.iterrows():
        i = angles.index(r["angle_deg"])
        j = xs.index(r["x"])
        grid[i, j] = index[r["cell_class"]]
        locks[i, j] = r["reference"] == Status.SELF_LOCKING
        if locks[i, j]:
            ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="///",
                                   lw=0, color="k", alpha=0.45))
        if not r["agrees"]:
            ax.text(j, i, "!", ha="center", va="center", fontsize=11, fontweight="bold")
    ax.imshow(grid, cmap=cmap, vmin=-0.5, vmax=len(classes) - 0.5, origin="lower",
              aspect="auto", zorder=0)
    _boundary(ax, locks)
    ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7)
    ax.set_yticks(range(len(angles)), [f"{a:g}" for a in angles], fontsize=7)
    ax.set_xlabel(panel["x_label"])
    ax.set_ylabel("shaft angle [deg]")
    ax.set_title(f"{panel['key']}: {panel['title']}", fontsize=9)


def stability_map(cells, panels: list[dict], classes):
    """``cardan stress`` map: one panel per slice, shaft angle (rows) against the panel's quantity.

    Colour: Exudyn's class; hatching: the reference self-locks; ``!``: the two disagree; black line:
    the reference's self-locking boundary.

    Parameters
    ----------
    cells : DataFrame
        One row per cell: ``panel``, ``angle_deg`` [deg], ``x``, ``cell_class``, ``reference``
        (its status) and ``agrees``.
    panels : list of dict
        ``key``, ``title``, ``x_label``, ``x_values`` and ``angles`` [deg] of each panel.
    classes : sequence of str
        The cell classes in legend order (keys of :data:`CLASS_COLOURS`).
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    ncols = min(3, len(panels))
    nrows = -(-len(panels) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.8 * ncols, 4.0 * nrows), squeeze=False,
                             constrained_layout=True)
    cmap = ListedColormap([CLASS_COLOURS[c] for c in classes])
    index = {c: i for i, c in enumerate(classes)}
    for ax, panel in zip(axes.flat, panels, strict=False):
        _stability_panel(ax, cells[cells["panel"] == panel["key"]], panel, index, cmap, classes)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    handles = [Patch(color=CLASS_COLOURS[c], label=c) for c in classes]
    handles.append(Patch(facecolor="white", hatch="///", edgecolor="k",
                         label="reference self-locks"))
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=8)
    return fig
