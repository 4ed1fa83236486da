"""The converged result along the line as a CSV table (-rod_table FILE.csv) and the
regions' summary beside it (FILE's stem + ``_regions.csv``; the run's final summary
prints it too, cli/messages.summary) and the ends' numbers (FILE's stem + ``_ends.csv``: one
row a number, ``quantity,value,unit``: the fairlead's and anchor's forces, the anchor's
uplift flag, the touchdown and the grounded length, ENDS_NUMBERS, those the run has,
for a run with the riser numbers)
(docs/output.md, docs/riser.md §5).

One row per vertex: S, x, y, z (absolute), u1, u2 (the signed curvatures about d1 and
d2) and every result along the line the run has (TABLE_DATASETS, those of its terms and
reports), a header row naming each column with its unit, e.g. ``effective_tension (N)``.

The table is written by rank 0: each rank formats its own vertices' rows and rank 0
gathers the text, in rank order, into one file (a CSV is one sequential text file, of
the size of the vertex datasets, a fraction of the HDF5 result; a collective MPI-IO
write of text rows of varying length would need their byte offsets for no gain at this
size). It is written only after the run converged, to the run's own partial name and
renamed when complete, like the HDF5 result (io/results.py): a run that did not
converge, diverged or was stopped leaves no table. Collective.
"""

import contextlib
import io as text_io
import os

import numpy as np

from petsc_rod.errors import RodInputError, RodIOError, on_every_rank
from petsc_rod.io import outputs
from petsc_rod.io.results import DATASET_UNITS, check_output_path, partial_name
from petsc_rod.quantities import riser_numbers

# The datasets of the table after S, x, y, z, u1, u2, in this order, where the run has
# them.
TABLE_DATASETS = ("curvature", "bend_radius", "bending_moment", "torque", "shear",
                  "effective_tension", "wall_tension", "external_pressure",
                  "internal_pressure", "von_mises", "utilisation", "declination",
                  "seabed_reaction", "seabed_height", "friction_force", "friction_state",
                  "axial_strain", "axial_tension", "section")
# The ends' numbers (quantities/line_results.py, quantities/riser_numbers.py), in this order.
ENDS_NUMBERS = ("fairlead_tension", "fairlead_horizontal", "fairlead_vertical",
                "fairlead_force_x", "fairlead_force_y", "fairlead_force_z", "anchor_tension",
                "anchor_horizontal", "anchor_vertical", "anchor_uplift", "top_tension",
                "top_angle", "touchdown_S", "touchdown_x", "touchdown_y", "grounded_length")
# The regions' table: its columns and the attributes they come from.
REGION_COLUMNS = (("S_from (m)", None), ("S_to (m)", None),
                  ("max_effective_tension (N)", "region_max_tension"),
                  ("max_effective_tension_S (m)", "region_max_tension_S"),
                  ("min_bend_radius (m)", "region_min_bend_radius"),
                  ("min_bend_radius_S (m)", "region_min_bend_radius_S"),
                  ("max_bending_moment (N m)", "region_max_bending_moment"),
                  ("max_bending_moment_S (m)", "region_max_bending_moment_S"))


def regions_path(path):
    """The regions' table beside the table ``path``: ``run.csv`` -> ``run_regions.csv``."""
    stem, extension = os.path.splitext(path)
    return f"{stem}_regions{extension or '.csv'}"


def ends_path(path):
    """The ends' table beside the table ``path``: ``run.csv`` -> ``run_ends.csv``."""
    stem, extension = os.path.splitext(path)
    return f"{stem}_ends{extension or '.csv'}"


def check_table_path(path, output, comm):
    """Refuse, before any work, a -rod_table (and its regions' and ends' files) that
    could not be written (io.results.check_output_path), or one that names the
    -rod_output file. Collective."""
    for name in (path, regions_path(path), ends_path(path)):
        if output and os.path.abspath(name) == os.path.abspath(output):
            raise RodInputError(f"-rod_table {path}: it (or its regions' table {name}) is "
                                f"the -rod_output file; name another file")
        check_output_path(name, comm, "-rod_table")


def discard(path, comm, say):
    """After a run that did not converge: no table is written, and a table (and its
    regions') left at ``path`` by an earlier run is removed, so that no table stands
    beside this run's result file as if it were its. Collective."""
    names = [name for name in (path, regions_path(path), ends_path(path))
             if os.path.exists(name)]
    comm.tompi4py().barrier()
    if comm.getRank() == 0:
        for name in names:
            with contextlib.suppress(FileNotFoundError):
                os.remove(name)
    text = f"; removed {' and '.join(names)}, an earlier run's" if names else ""
    say(f"petsc_rod: no table written (-rod_table {path}): the run did not converge{text}")


def final_record(problem):
    """(vertex datasets with the terms' and reports' and r absolute, and the effective
    tension n.t where none wrote it; their attributes) of the problem's state
    (outputs.collect). Collective."""
    collected = outputs.collect(problem)
    vertex = collected.vertex
    if "effective_tension" not in vertex:       # a plain rod's (quantities/line_results.py)
        vertex["effective_tension"] = riser_numbers.effective_tension(vertex)
    return vertex, collected.attributes


def table_columns(vertex, units):
    """(header names with units, (n, columns) values) of this rank's vertices; ``units``
    the terms' and reports' ({dataset: unit}, {attribute: unit})."""
    names = ["S (m)", "x (m)", "y (m)", "z (m)", "u1 (rad/m)", "u2 (rad/m)"]
    columns = [vertex["S"], *vertex["r"].T, vertex["u"][:, 0], vertex["u"][:, 1]]
    # the effective tension final_record adds on a plain rod has the riser numbers' unit
    known = {**DATASET_UNITS, "effective_tension": riser_numbers.DATASET_UNITS[
        "effective_tension"], **units[0]}
    for key in TABLE_DATASETS:
        if key in vertex:
            values = np.asarray(vertex[key], dtype=float)
            if values.ndim == 2:        # a vector along the line: its global components
                names += [f"{key}_{axis} ({known[key]})" for axis in "xyz"]
                columns += list(values.T)
            else:
                names.append(f"{key} ({known[key]})")
                columns.append(values)
    return names, np.column_stack(columns)


def _rows(values):
    """CSV text of the rows ``values`` (n, columns), 12 significant digits."""
    buffer = text_io.StringIO()
    np.savetxt(buffer, values, fmt="%.12g", delimiter=",")
    return buffer.getvalue()


def region_rows(attributes):
    """(header, rows text) of the regions' table; None without regions."""
    if "region_names" not in attributes:
        return None
    header = ",".join(["region"] + [name for name, _ in REGION_COLUMNS])
    lines = []
    for i, name in enumerate(attributes["region_names"]):
        values = list(attributes["region_bounds"][i]) + [attributes[key][i] for _, key in
                                                          REGION_COLUMNS[2:]]
        lines.append(",".join([name] + [f"{v:.12g}" for v in values]))
    return header, "\n".join(lines) + "\n"


def ends_rows(attributes, units):
    """The ends' table as text (module docstring); None for a run without the riser
    numbers (a rod of the paper's kind, a cantilever: its end forces are in the file)."""
    if "top_tension" not in attributes:
        return None
    present = [key for key in ENDS_NUMBERS if key in attributes]
    return "quantity,value,unit\n" + "".join(
        f"{key},{float(attributes[key]):.12g},{units.get(key, '')}\n" for key in present)


def _write(path, partial, text):
    """``text`` into ``partial``, renamed to ``path`` (rank 0)."""
    try:
        with open(partial, "w") as handle:
            handle.write(text)
        os.replace(partial, path)
    except OSError as error:
        with contextlib.suppress(OSError):
            os.remove(partial)
        raise RodIOError(f"-rod_table {path}: writing failed ({error.strerror}); no table "
                         "is left") from None


def write_tables(path, comm, vertex, attributes, units):
    """The CSV table at ``path`` and the regions' beside it (module docstring); ``units``
    as table_columns'. Collective."""
    names, values = table_columns(vertex, units)
    pieces = comm.tompi4py().gather(_rows(values), root=0)
    files = [(path, ",".join(names) + "\n" + "".join(pieces or []))]
    rows = region_rows(attributes)
    if rows is not None:
        files.append((regions_path(path), rows[0] + "\n" + rows[1]))
    ends = ends_rows(attributes, units[1])
    if ends is not None:
        files.append((ends_path(path), ends))
    partials = [partial_name(name, comm) for name, _ in files]

    def write_all():
        if comm.getRank() == 0:
            for (name, text), partial in zip(files, partials):
                _write(name, partial, text)
    on_every_rank(comm, write_all)


def finish_run(problem, path, say):
    """After a converged run: the table written when ``path`` (-rod_table) is given (the
    regions' summary is the run's final summary's, cli/messages.summary). Collective."""
    if not path:
        return
    vertex, attributes = final_record(problem)
    if path:
        write_tables(path, problem.mesh.comm, vertex, attributes, problem.units())
        say(f"petsc_rod: table {path}" + (f", regions {regions_path(path)}"
                                          if "region_names" in attributes else "")
            + (f", ends {ends_path(path)}" if ends_rows(attributes, {}) else ""))
