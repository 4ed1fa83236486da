"""Figures from a result file (matplotlib only; never PETSc, never a running solve).

    python -m petsc_rod.plots paper.h5 paper.png

draws the centreline projected on the xy, xz and yz planes, and the strains u1, u2,
u3 against S: the paper's Figures 1 and 3 for one solution (docs/method.md §8); for a
riser (a file with the riser datasets), the profile with the seabed, the effective
tension and the curvature against S (riser/figure.py).
"""

import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from petsc_rod.riser.figure import draw_riser  # noqa: E402

DPI = 110


def plot_result(path, output):
    """Write the figure of result file ``path`` to ``output`` (PNG)."""
    figure = result_figure(path)
    figure.savefig(output, dpi=DPI)
    plt.close(figure)


def result_figure(path):
    """The figure of result file ``path``: three projections of r, and u against S."""
    with h5py.File(path, "r") as f:
        S, r, u = f["S"][:], f["r"][:], f["u"][:]
        converged = int(f.attrs["converged"])
        energy = float(f.attrs["energy"])
        riser = riser_data(f) if "effective_tension" in f else None
    if riser is not None:               # a riser scene (petsc_rod/riser/figure.py)
        figure = plt.figure(figsize=(16, 4.5), layout="constrained")
        draw_riser(figure, {"S": S, "r": r, "u": u, **riser})
        return titled(figure, path, converged, energy)
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
    return titled(figure, path, converged, energy)


def titled(figure, path, converged, energy):
    """``figure`` titled with the file's outcome."""
    status = "converged" if converged else "NOT converged"
    figure.suptitle(f"{path}: {status}, energy {energy:.6g} J")
    return figure


def riser_data(f):
    """What the riser figure needs beyond S, r, u from an open result file."""
    seabed = f["parameters"].attrs.get("seabed", "") if "parameters" in f else ""
    touchdown = ((float(f.attrs["touchdown_S"]), f.attrs["touchdown_position"][:])
                 if "touchdown_S" in f.attrs else None)
    sections = None
    if "section_names" in f.attrs:          # a line of sections (riser/section_numbers.py)
        names = [n.decode() if isinstance(n, bytes) else str(n)
                 for n in f.attrs["section_names"]]
        sections = (names, f.attrs["section_bounds"][:])
    return {"tension": f["effective_tension"][:], "touchdown": touchdown,
            "seabed": None if isinstance(seabed, (str, bytes)) else float(seabed),
            "sections": sections}


def main(argv):
    if len(argv) != 3:
        sys.stderr.write("usage: python -m petsc_rod.plots RESULT.h5 FIGURE.png\n")
        return 2
    plot_result(argv[1], argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
