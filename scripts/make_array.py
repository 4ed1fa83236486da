"""Writes the array scene options/array_10x10.dat: a MoorDyn version 2 input file of
rows x columns floaters on a shared-anchor honeycomb (docs/systems.md, "The array").

    python scripts/make_array.py [rows] [columns] [file]

Floaters and anchors sit on the two sublattices of a honeycomb of bond R = 400 m
(plan): floater (m, n) at m a1 + n a2, a1 = (sqrt(3) R, 0), a2 = (sqrt(3) R / 2,
3 R / 2), row n shifted by -floor(n / 2) a1 so that the patch is rectangular; its three
lines at 90, 330 and 210 degrees go to the anchors at +R e_y and at R (+-sqrt(3)/2,
-1/2), each anchor inside the patch shared by three floaters (the boundary's by one or
two). Water 100 m deep; each line 415 m of the OC3 chain (0.09 m, 77.7066 kg/m, EA
384.243 MN, EI 0: the reader's rule), from its anchor on the seabed to a fairlead 5 m
from the floater's axis and 15 m below its reference point at the surface: at rest a
horizontal pull of 200 kN and 150 m on the seabed (the elastic catenary). Each floater
is a free body (spar-like: 2000 m^3 displaced at its reference point, its centre of
gravity 20 m below it) whose mass balances its lines' vertical pull at rest, so the
array is at rest in equilibrium; a steady 50 kN force along x on every floater (wind,
current and drift: EXTERNAL LOADS) moves it.
"""

import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
BOND, DEPTH, LENGTH, RADIUS, DRAFT = 400.0, 100.0, 415.0, 5.0, 15.0      # m
VOLUME, CG, FORCE, RHO, G = 2000.0, -20.0, 5e4, 1025.0, 9.80665
EA, MASS, DIAMETER = 384.243e6, 77.7066, 0.09
HEADINGS = np.radians([90.0, 330.0, 210.0])     # the order of layout's anchors


def top_pull():
    """The vertical force of one line on its fairlead at rest, N (elastic catenary)."""
    from petsc_rod.validation.elastic_catenary import elastic_catenary
    weight = (MASS - RHO * np.pi * DIAMETER**2 / 4) * G
    line = elastic_catenary(LENGTH, weight, EA, BOND - RADIUS, DEPTH - DRAFT)
    return line.V_A + weight * (LENGTH - line.grounded)


def layout(rows, columns):
    """(floaters (rows * columns, 2), anchors (n_anchors, 2), lines (n_lines, 2): the
    anchor and floater index of each line), m, the floaters in row order."""
    a1, a2 = np.array([np.sqrt(3) * BOND, 0.0]), np.array([np.sqrt(3) * BOND / 2, 1.5 * BOND])
    n, m = np.divmod(np.arange(rows * columns), columns)
    m = m - n // 2
    floaters = m[:, None] * a1 + n[:, None] * a2
    # the anchors of floater (m, n): B(m, n), B(m + 1, n - 1), B(m, n - 1), with
    # B(m, n) = A(m, n) + (0, R): at 90, 330 and 210 degrees
    keys = np.stack([np.stack([m, n], -1), np.stack([m + 1, n - 1], -1),
                     np.stack([m, n - 1], -1)], 1)                      # (floaters, 3, 2)
    unique, index = np.unique(keys.reshape(-1, 2), axis=0, return_inverse=True)
    anchors = unique[:, :1] * a1 + unique[:, 1:] * a2 + (0.0, BOND)
    lines = np.stack([index.ravel(), np.repeat(np.arange(rows * columns), 3)], -1)
    return floaters, anchors, lines


def table(title, columns, units, rows):
    """A MoorDyn section: its header line, the column names, the units, the rows."""
    return [f"{'-' * 22} {title} {'-' * max(3, 54 - len(title))}", columns, units, *rows]


def deck(rows, columns):
    """The MoorDyn version 2 file's text."""
    floaters, anchors, lines = layout(rows, columns)
    mass = RHO * VOLUME - 3 * top_pull() / G
    first = len(anchors) + 1
    fairleads = [f"{first + k}  Body{lines[k, 1] + 1}  {RADIUS * np.cos(HEADINGS[k % 3]):.4f}  "
                 f"{RADIUS * np.sin(HEADINGS[k % 3]):.4f}  {-DRAFT}  0  0  0  0"
                 for k in range(len(lines))]
    out = ["--------------------- MoorDyn Input File -------------------------------------",
           f"petsc_rod array scene: {rows} x {columns} floaters on a shared-anchor "
           f"honeycomb, {len(anchors)} anchors, {len(lines)} lines (scripts/make_array.py)"]
    out += table("LINE TYPES",
                 "TypeName  Diam  Mass/m  EA  BA/-zeta  EI  Cd  Ca  CdAx  CaAx",
                 "(name)  (m)  (kg/m)  (N)  (N-s/-)  (N-m^2)  (-)  (-)  (-)  (-)",
                 [f"chain  {DIAMETER}  {MASS}  {EA:.6g}  -0.8  0  1.6  1.0  0.1  0.0"])
    out += table("BODIES",
                 "ID  Attachment  X0  Y0  Z0  r0  p0  y0  Mass  CG*  I*  Volume  CdA*  Ca",
                 "(#)  (-)  (m)  (m)  (m)  (deg)  (deg)  (deg)  (kg)  (m)  (kg-m^2)  (m^3)  "
                 "(m^2)  (-)",
                 [f"{k + 1}  Free  {x:.3f}  {y:.3f}  0.0  0  0  0  {mass:.3f}  {CG}  0  "
                  f"{VOLUME}  0  0" for k, (x, y) in enumerate(floaters)])
    out += table("POINTS", "ID  Attachment  X  Y  Z  Mass  Volume  CdA  Ca",
                 "(#)  (-)  (m)  (m)  (m)  (kg)  (m^3)  (m^2)  (-)",
                 [f"{k + 1}  Fixed  {x:.3f}  {y:.3f}  {-DEPTH}  0  0  0  0"
                  for k, (x, y) in enumerate(anchors)] + fairleads)
    out += table("LINES", "ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs",
                 "(#)  (name)  (#)  (#)  (m)  (-)  (-)",
                 [f"{k + 1}  chain  {anchor + 1}  {first + k}  {LENGTH}  20  -"
                  for k, (anchor, _) in enumerate(lines)])
    out += table("EXTERNAL LOADS", "ID  Object  Fext  Blin  Bquad  CSys",
                 "(#)  (name)  (N)  (-)  (-)  (-)",
                 [f"{k + 1}  Body{k + 1}  {FORCE:.6g}|0|0  0  0  G"
                  for k in range(len(floaters))])
    out += [f"{'-' * 22} OPTIONS {'-' * 47}",
            f"{DEPTH}   WtrDpth   water depth (m)",
            f"{RHO}  WtrDnsty  water density (kg/m^3)",
            "3.0e6   kBot      bottom stiffness (Pa/m)",
            "0.001   dtM       time step (s)",
            "--------------------------- need this line ----------------------------------"]
    return "\n".join(out) + "\n"


def main(rows=10, columns=10, path=None):
    path = path or os.path.join(HERE, os.pardir, "options", f"array_{rows}x{columns}.dat")
    with open(path, "w") as file:
        file.write(deck(rows, columns))
    print(f"{path}: {rows * columns} floaters")


if __name__ == "__main__":
    main(*(int(v) for v in sys.argv[1:3]), *sys.argv[3:4])
