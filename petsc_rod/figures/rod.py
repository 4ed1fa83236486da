"""The figure of a plain rod (a file without the riser datasets): the centreline
projected on the xy, xz and yz planes, and the strains u1, u2, u3 against S (the
paper's Figures 1 and 3 for one solution, docs/method.md §8)."""

import matplotlib.pyplot as plt

from petsc_rod.figures.titles import result_title


def rod_figure(result):
    """Four panels: three projections of r and u against S, 16 x 4 inches."""
    r, S, u = result.r, result.S, result.u
    figure, axes = plt.subplots(1, 4, figsize=(16, 4), layout="constrained")
    for axis, (i, j), names in zip(axes, ((0, 1), (0, 2), (1, 2)), ("xy", "xz", "yz")):
        axis.plot(r[:, i], r[:, j], "-", lw=1.5)
        axis.plot(r[[0, -1], i], r[[0, -1], j], "o", ms=4)
        axis.set_xlabel(f"{names[0]} (m)")
        axis.set_ylabel(f"{names[1]} (m)")
        axis.set_aspect("equal", adjustable="datalim")
        axis.set_title(f"projection on the {names} plane")
    for k in range(3):
        axes[3].plot(S, u[:, k], label=f"u{k + 1}")
    axes[3].set_xlabel("S (m)")
    axes[3].set_ylabel("strain (1/m)")
    axes[3].legend()
    axes[3].set_title("bending u1, u2 and twist u3")
    figure.suptitle(result_title(result))
    return figure
