"""Plots: functions take data and an optional Axes and return the Figure."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from reference.scene import PAIR_NAMES  # noqa: E402


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


def input_torque(tables: dict[str, object], ax=None):
    """Drive torque against input angle, one line per labelled table."""
    return _against_input_angle(tables, lambda t: t["torque_in"], "input torque [N m]", ax)


def reactions(table, title: str = "", axes=None):
    """Per pair: magnitude of the radial force and of the bending moment against input angle."""
    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    fig = axes[0].figure
    angle = np.degrees(table["theta_in"]) % 360
    for pair in PAIR_NAMES:
        f = np.hypot(table[f"{pair}_fx"], table[f"{pair}_fy"])
        m = np.hypot(table[f"{pair}_mx"], table[f"{pair}_my"])
        axes[0].plot(angle, f, ".", ms=1.5, label=pair)
        axes[1].plot(angle, m, ".", ms=1.5, label=pair)
    axes[0].set_ylabel("radial reaction force [N]")
    axes[1].set_ylabel("bending reaction moment [N m]")
    for ax in axes:
        ax.set_xlabel("input angle [deg]")
        ax.set_xlim(0, 360)
        ax.set_yscale("log")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, markerscale=6)
    if title:
        fig.suptitle(title)
    return fig


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


def save(fig, path) -> None:
    fig.savefig(path, dpi=130)
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
        sel = rows[(rows["scene"] == scene) & (rows["status"] == "ok")]
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
