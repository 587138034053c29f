"""Plots: functions take data and an optional Axes and return the Figure."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from reference.schema import Status  # noqa: E402


def _axes(ax):
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4.2), constrained_layout=True)
        return fig, ax
    return ax.figure, ax


def _against_input_angle(tables: dict[str, object], values, ylabel: str, ax=None):
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
    """omega_out/omega_in against input angle, one line per labelled table."""
    return _against_input_angle(tables, lambda t: t["omega_out"] / t["omega_in"],
                                "omega_out / omega_in [-]", ax)


def efficiency_history(tables: dict[str, object], title: str = "", ax=None, ylim=(0.0, 1.05)):
    """Instantaneous efficiency of eq. (18) against time (Figures 4, 6, 7 of the paper).

    Where the input power changes sign eq. (18) is unbounded; the axis is clipped to ``ylim``.
    """
    fig, ax = _axes(ax)
    for label, t in tables.items():
        ax.plot(t["t"], t["efficiency"], lw=0.9, label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("instantaneous efficiency, eq. (18) [-]")
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9)
    return fig


def pair_losses(table, title: str = ""):
    """Power loss of the spider pairs (left) and of the shaft-frame pairs (right), Figure 5."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for ax, pairs in zip(axes, (("input_spider", "spider_output"), ("frame_input", "output_frame")),
                         strict=True):
        for pair in pairs:
            ax.plot(table["t"], table[f"power_loss_{pair}"], lw=0.9, label=pair)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("power loss [W]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    if title:
        fig.suptitle(title)
    return fig


def efficiency_against_paper(rows, x: str, xlabel: str, ax=None):
    """Mean efficiency (both definitions, each parameter set) against the paper's values."""
    fig, ax = _axes(ax)
    first = True
    for label, df in rows.items():
        ax.plot(df[x], df["mean_efficiency"], "o-", label=f"{label}: 1 - W_loss / W_in")
        ax.plot(df[x], df["mean_instantaneous_efficiency"].clip(-0.1, 1.1), "x:",
                label=f"{label}: time average of eq. (18)")
        if first:
            ax.plot(df[x], df["paper_mean_efficiency"], "ks", mfc="none", label="paper")
            first = False
    ax.set_xlabel(xlabel)
    ax.set_ylabel("mean efficiency [-]")
    ax.set_ylim(-0.1, 1.1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return fig


def save(fig, path, dpi: int = 130) -> None:
    """Write ``fig`` to ``path`` and close it."""
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def work_precision(rows, speed_ratio_level: float, efficiency_level: float):
    """Error against wall time per simulated second, log-log, one column per bench scene.

    Top row: the scene's accuracy measure (speed-ratio error without friction, mean-efficiency
    error with friction) with the target level dashed; bottom row: drive-torque error after the
    first revolution. One line per configuration, points along its step-size ladder.
    """
    scenes = list(dict.fromkeys(rows["scene"]))
    fig, axes = plt.subplots(2, len(scenes), figsize=(4.6 * len(scenes), 7.5), squeeze=False,
                             constrained_layout=True)
    markers = {"exudyn": "o", "mujoco": "s", "reference": "^"}
    for j, scene in enumerate(scenes):
        sel = rows[(rows["scene"] == scene) & (rows["status"] == Status.OK)]
        friction = scene.startswith("friction-")
        top = "mean_efficiency_error" if friction else "speed_ratio_error"
        level = efficiency_level if friction else speed_ratio_level
        for i, (key, label) in enumerate(((top, "mean-efficiency error" if friction
                                            else "max speed-ratio error"),
                                           ("torque_in_error_steady",
                                            "drive-torque error after rev. 1 (rel.)"))):
            ax = axes[i][j]
            for config, part in sel.groupby("config", sort=False):
                part = part.sort_values("steps_per_revolution")
                y = part[key].astype(float).clip(lower=1e-16)
                if not y.notna().any():
                    continue
                ax.loglog(part["wall_per_simulated_s"], y, marker=markers.get(part["engine"].iloc[0], "o"),
                          ms=4, lw=1, label=config)
            if i == 0:
                ax.axhline(level, color="k", ls="--", lw=0.8)
                ax.set_title(scene)
            ax.set_xlabel("wall time per simulated second [s]")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=6)
    return fig


def close(fig) -> None:
    plt.close(fig)


CLASS_COLOURS = {"converged": "#4caf50", "drift": "#ff9800", "self_locking": "#5c8fd6",
                 "integration_failure": "#e53935", "error": "#212121"}


def stability_map(cells, panels: list[dict], classes):
    """``cardan stress`` map: one panel per slice, shaft angle (rows) against the panel's
    quantity (columns, one cell per value). Colour: Exudyn's class; hatching: the reference
    self-locks; ``!``: the two disagree; black line: the reference's self-locking boundary."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch, Rectangle

    ncols = min(3, len(panels))
    nrows = -(-len(panels) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.8 * ncols, 4.0 * nrows), squeeze=False,
                             constrained_layout=True)
    cmap = ListedColormap([CLASS_COLOURS[c] for c in classes])
    index = {c: i for i, c in enumerate(classes)}
    for ax, panel in zip(axes.flat, panels, strict=False):
        sel = cells[cells["panel"] == panel["key"]]
        xs, angles = list(panel["x_values"]), list(panel["angles"])
        grid = np.full((len(angles), len(xs)), np.nan)
        locks = np.zeros_like(grid, dtype=bool)
        for _, r in sel.iterrows():
            i, j = angles.index(r["angle_deg"]), xs.index(r["x"])
            grid[i, j] = index[r["cell_class"]]
            locks[i, j] = r["reference"] == Status.SELF_LOCKING
            if locks[i, j]:
                ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="///",
                                       lw=0, color="k", alpha=0.45))
            if not r["agrees"]:
                ax.text(j, i, "!", ha="center", va="center", fontsize=11, fontweight="bold")
        ax.imshow(grid, cmap=cmap, vmin=-0.5, vmax=len(classes) - 0.5, origin="lower",
                  aspect="auto", zorder=0)
        for i in range(len(angles)):  # boundary: edges between cells of different reference state
            for j in range(len(xs)):
                if j + 1 < len(xs) and locks[i, j] != locks[i, j + 1]:
                    ax.plot([j + 0.5, j + 0.5], [i - 0.5, i + 0.5], "k", lw=2)
                if i + 1 < len(angles) and locks[i, j] != locks[i + 1, j]:
                    ax.plot([j - 0.5, j + 0.5], [i + 0.5, i + 0.5], "k", lw=2)
        ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7)
        ax.set_yticks(range(len(angles)), [f"{a:g}" for a in angles], fontsize=7)
        ax.set_xlabel(panel["x_label"])
        ax.set_ylabel("shaft angle [deg]")
        ax.set_title(f"{panel['key']}: {panel['title']}", fontsize=9)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    handles = [Patch(color=CLASS_COLOURS[c], label=c) for c in classes]
    handles.append(Patch(facecolor="white", hatch="///", edgecolor="k",
                         label="reference self-locks"))
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), fontsize=8)
    return fig
