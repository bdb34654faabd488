"""The moment-rotation curve of a tape spring in pure bending, like the paper's Fig. 4."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from tapespring.scenarios.bending import BendingResult

__all__ = ["plot_bending"]

_COLOURS = {0: "tab:blue", 1: "tab:red"}
_LABELS = {0: "loading", 1: "unloading"}


def plot_bending(result: BendingResult, *, ax: Axes | None = None, summary: bool = True) -> Axes:
    """Plot the moment-rotation curve like the paper's Fig. 4.

    Each branch (loading, unloading) is one line in its colour: solid where the equilibria are
    stable under rotation control, dashed where they are not; a snap (a jump at fixed angle to the
    stable equilibrium beyond a limit point) is a thin dotted line. The curve starts at the
    origin, and passes through the located peak moment, snap and heel.

    Parameters
    ----------
    result : BendingResult
        The curve.
    ax : matplotlib Axes, optional
        Where to draw; a new figure is made if None.
    summary : bool
        Mark the peak moment, the snap and heel angles, and the analytical residual moment.

    Returns
    -------
    matplotlib Axes
    """
    import matplotlib.pyplot as plt

    from tapespring.scenarios.bending import summarize

    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.4), constrained_layout=True)
    th, m, st, jp = result.theta_deg, result.moment, result.stable, result.jump
    for b in (0, 1):
        sel = np.nonzero(result.branch == b)[0]
        if b == 1 and sel.size:
            # The unloading branch starts where loading ended.
            sel = np.concatenate([[sel[0] - 1], sel])
        if sel.size < 2:
            continue
        # Runs of consecutive segments with the same style, drawn as single lines.
        styles = []
        for i, j in zip(sel[:-1], sel[1:], strict=True):
            styles.append("jump" if jp[j] else ("stable" if st[i] and st[j] else "unstable"))
        start = 0
        for k in range(1, len(styles) + 1):
            if k < len(styles) and styles[k] == styles[start]:
                continue
            idx = sel[start : k + 1]
            style = styles[start]
            ax.plot(
                th[idx],
                m[idx],
                color=_COLOURS[b],
                linestyle={"stable": "-", "unstable": "--", "jump": ":"}[style],
                linewidth={"stable": 1.8, "unstable": 1.1, "jump": 1.0}[style],
            )
            start = k
        ax.plot([], [], color=_COLOURS[b], linewidth=1.8, label=f"{_LABELS[b]} (stable)")
    if not st.all():
        ax.plot([], [], color="0.3", linestyle="--", linewidth=1.1, label="unstable")
    if jp.any():
        ax.plot([], [], color="0.3", linestyle=":", linewidth=1.0, label="snap (jump)")
    if summary and th.size > 1:
        s = summarize(result)
        ax.axhline(
            s.m_star_analytical,
            color="0.4",
            linestyle=":",
            linewidth=1.0,
            label=r"$(1\pm\nu)D\alpha$",
        )
        ax.plot(
            [s.theta_at_m_max_deg],
            [s.m_max],
            "o",
            color="k",
            markersize=4,
            label=rf"$M^{{max}}$ = {s.m_max:.3f} N m at {s.theta_at_m_max_deg:.2f}$^\circ$",
        )
        for angle, name, marker in (
            (s.theta_snap_deg, "snap", "v"),
            (s.theta_heel_deg, "heel", "^"),
        ):
            if angle is not None:
                k = int(np.argmin(np.abs(th - angle)))
                ax.plot(
                    [angle],
                    [m[k]],
                    marker,
                    color="k",
                    markersize=4,
                    label=f"{name} at {angle:.2f}$^\\circ$",
                )
    ax.axhline(0.0, color="0.8", linewidth=0.6)
    ax.axvline(0.0, color="0.8", linewidth=0.6)
    ax.set_xlabel(r"bending angle $\theta$ [deg]")
    ax.set_ylabel(r"bending moment $M$ [N m]")
    setup = result.setup
    ax.set_title(
        f"tape spring L = {setup.length * 1e3:.0f} mm, R = {setup.radius * 1e3:.2f} mm, "
        f"alpha = {setup.alpha_deg:.2f} deg, t = {setup.thickness * 1e3:.3f} mm",
        fontsize=9,
    )
    ax.legend(fontsize=8, loc="best")
    return ax
