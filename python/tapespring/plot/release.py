"""The free motion of a released tape spring: its end's angle and the energy balance."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tapespring.scenarios.release import ReleaseResult

__all__ = ["plot_release"]

_ENERGY_STYLE = {
    "kinetic": ("tab:red", "-"),
    "strain": ("tab:blue", "-"),
    "gravity": ("tab:brown", "-"),
    "viscous": ("tab:green", "--"),
    "numerical": ("tab:grey", ":"),
}


def plot_release(result: ReleaseResult) -> Figure:
    """Two stacked panels sharing the time axis (from the release, in s): the rotation of the
    free end about y [deg], and the energy terms [mJ] with their sum, which stays at the energy
    of the release when the balance closes. The energy legend sits where it covers no curve:
    in a free corner of the panel, else above it.

    Parameters
    ----------
    result : ReleaseResult
        A release run.

    Returns
    -------
    matplotlib Figure
    """
    import matplotlib.pyplot as plt

    from ._legend import place_legends

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7.0, 6.0))
    t = result.time_s
    top.plot(t, result.theta_deg, color="k", lw=1.2)
    zero = top.axhline(0.0, color="0.6", lw=0.6)
    top.set_ylabel("end rotation about y [deg]")
    sense = "opposite" if result.setup.fold_deg > 0 else "equal"
    top.set_title(
        f"release from {result.setup.fold_deg:+.0f} deg ({sense} sense), "
        f"tip {result.setup.tip_mass * 1e3:.0f} g, eta = {result.setup.eta:g} s, "
        f"rho_inf = {result.setup.rho_inf:g}",
        fontsize=10,
    )
    e = result.energy
    total = e["kinetic"] + e["strain"] + e["gravity"] + e["viscous"] + e["numerical"]
    total = total - e["work_loads"] - e["work_prescribed"]
    for name, (colour, style) in _ENERGY_STYLE.items():
        if name == "gravity" and not result.setup.gravity:
            continue
        bottom.plot(t, 1e3 * e[name], color=colour, ls=style, lw=1.2, label=name)
    bottom.plot(t, 1e3 * total, color="k", lw=0.8, label="sum")
    bottom.set_xlabel("time after release [s]")
    bottom.set_ylabel("energy [mJ]")
    for ax in (top, bottom):
        ax.grid(True, lw=0.4, alpha=0.5)
    # In a corner free of the curves if there is one, else above the panel.
    place_legends(fig, [(bottom, {"fontsize": 8})], ignore=[zero])
    return fig
