"""-rod_modes: the natural modes about the converged state after the last step
(analysis/modes.py, docs/modes.md): found before the result file is finished (its group
``modes``), then said as the run's lines (a table of the modes) and written as the CSV
files of -rod_modes_table: the modes' table and their shapes along the line."""

import importlib.util
import os
import time

import numpy as np
from petsc4py import PETSc

from petsc_rod.analysis.mass import MISSING_MASS, MassSettings, mass_known
from petsc_rod.analysis.modes import (CLASSES, PREFIX, RESIDUAL, SUBSPACE,
                                      default_subspace,
                                      ModesRefused, check_options, modes_count,
                                      solve_modes, symmetrised_text)
from petsc_rod.errors import RodInputError, RodIOError, petsc_message
from petsc_rod.cli.options import modes_asked
from petsc_rod.figures.modes import shapes_path
from petsc_rod.io.results import check_output_path

# SLEPc's Krylov-Schur (its default EPS) needs ncv >= nev + 1; the other types ncv >= nev
KRYLOV_SCHUR = "krylovschur"
TABLE_COLUMNS = ("mode", "frequency_Hz", "period_s", "omega_rad_s", "modal_mass_kg",
                 "class", *(f"share_{name.replace('-', '_')}" for name in CLASSES))
SHAPE_COLUMNS = ("mode", "S_m", "offset_x_m", "offset_y_m", "offset_z_m", "rotation_x_rad",
                 "rotation_y_rad", "rotation_z_rad", "curvature_1_per_m",
                 "curvature_2_per_m", "twist_per_m")


def mass_settings(values):
    return MassSettings(added_mass=values["rod_modes_added_mass"],
                        mass=values["rod_modes_mass"], inertia=values["rod_modes_inertia"])


def modes_band(text):
    """(fmin, fmax), Hz, of -rod_modes_range ``text`` 'FMIN,FMAX' (None: none);
    RodInputError unless 0 <= FMIN < FMAX, both finite."""
    if text is None:
        return None
    parts = text.split(",")
    try:
        band = tuple(float(part) for part in parts)
    except ValueError:
        band = ()
    if len(band) != 2 or not np.all(np.isfinite(band)) or not 0 <= band[0] < band[1]:
        raise RodInputError(f"-rod_modes_range {text}: expected FMIN,FMAX, two frequencies "
                            "in Hz with 0 <= FMIN < FMAX (e.g. 0.05,0.5)")
    return band


def check_subspace(count):
    """RodInputError, in one line, where the Krylov subspace (-rod_modes_eps_ncv, by
    default analysis/modes.default_subspace) is below what SLEPc
    needs for the modes asked (-rod_modes ``count``, or -rod_modes_eps_nev, which
    overrides it): ncv >= nev + 1 for Krylov-Schur (the default -rod_modes_eps_type),
    ncv >= nev for the others; SLEPc refuses it only inside the solve, after the
    equilibrium (a line's run and a system's: api/system_run.modes_request), or a value
    that is no whole number."""
    options = PETSc.Options(PREFIX)
    if not (options.hasName("eps_ncv") or options.hasName("eps_nev")):
        return
    try:
        nev = options.getInt("eps_nev", count)
        ncv = options.getInt("eps_ncv", default_subspace(count))
    except PETSc.Error:
        raise RodInputError("-rod_modes_eps_nev and -rod_modes_eps_ncv take whole numbers "
                            "(the modes the eigensolver computes, its Krylov subspace)") \
            from None
    kind = options.getString("eps_type", KRYLOV_SCHUR).lower()
    least = nev + 1 if kind == KRYLOV_SCHUR else nev
    if ncv < least:
        asked = (f"-rod_modes {count}" if nev == count else f"-rod_modes_eps_nev {nev}")
        given = (f"-rod_modes_eps_ncv {ncv}" if options.hasName("eps_ncv") else
                 f"the default -rod_modes_eps_ncv {ncv} (-rod_modes {count} + "
                 f"max({SUBSPACE}, {count} / 2))")
        raise RodInputError(f"{given}: {asked} needs a Krylov subspace of at least {least} "
                            f"vectors (SLEPc's {kind}: ncv >= nev"
                            f"{' + 1' if kind == KRYLOV_SCHUR else ''}); give "
                            f"-rod_modes_eps_ncv {least} or more")


def check_modes_inputs(values, scene, comm):
    """Refuse, before any work, -rod_modes on a uniform line that has neither a load nor
    -rod_modes_mass, -rod_modes_range malformed or beside -rod_modes,
    -rod_modes_table
    without either, and a -rod_modes_table (or its shapes' file) that could not be
    written or names another output. Collective."""
    modes_band(values["rod_modes_range"])
    if values["rod_modes"] and values["rod_modes_range"]:
        raise RodInputError("-rod_modes and -rod_modes_range: give one (the N lowest "
                            "modes, or every mode in a band)")
    if modes_asked(values) and importlib.util.find_spec("slepc4py") is None:
        raise RodInputError("-rod_modes needs slepc4py, which is not installed: install "
                            "Debian's python3-slepc4py (scripts/setup.sh does)")
    if modes_asked(values):
        try:
            check_options(comm)
        except PETSc.Error as error:
            raise RodInputError(f"SLEPc refused the modes' options: {petsc_message(error)}; "
                                "check the -rod_modes_eps_* and -rod_modes_st_* options") from None
    if values["rod_modes"]:
        check_subspace(values["rod_modes"])
    path = values["rod_modes_table"]
    if path and not modes_asked(values):
        raise RodInputError("-rod_modes_table needs -rod_modes N (the number of modes) "
                            "or -rod_modes_range FMIN,FMAX")
    if path:
        others = [values["rod_output"], values["rod_table"]]
        for name in (path, shapes_path(path)):
            if any(other and os.path.abspath(other) == os.path.abspath(name)
                   for other in others):
                raise RodInputError(f"-rod_modes_table {path}: it (or its shapes' file "
                                    f"{name}) is another output of the run; name another file")
            check_output_path(name, comm, "-rod_modes_table")
    if modes_asked(values) and not mass_known(scene, mass_settings(values)):
        raise RodInputError(f"{MISSING_MASS}: give -rod_modes_mass (kg/m)")


def check_modes_count(problem, values):
    """RodInputError, in one line, where -rod_modes N asks for more modes than the
    line's discretisation has (analysis/modes.modes_count, at the start: before the
    solve and its file). Counted (one factorisation) only where N is above the element
    count: every element's midpoint moves sideways with its mass, at least one mode an
    element. Collective."""
    count, elements = values["rod_modes"], problem.mesh.n_elements
    if not count or count <= elements:
        return
    available = modes_count(problem, mass_settings(values))
    if count > available:
        raise RodInputError(f"-rod_modes {count}: the line's discretisation has "
                            f"{available} modes ({elements} elements); ask for at most "
                            f"{available}, or for every mode in a band with "
                            "-rod_modes_range FMIN,FMAX (docs/modes.md)")


def solve_for_run(problem, values, writer):
    """(Modes or ModesRefused, seconds) of -rod_modes about the problem's converged state,
    the modes written into the result file where there is one (``writer``). Collective."""
    start = time.perf_counter()
    try:
        modes = solve_modes(problem, values["rod_modes"], mass_settings(values),
                            modes_band(values["rod_modes_range"]))
    except ModesRefused as refused:
        return refused, problem.mesh.global_max(time.perf_counter() - start)
    seconds = problem.mesh.global_max(time.perf_counter() - start)
    if writer is not None:
        writer.write_modes(modes)
    return modes, seconds


def report_modes(problem, values, found, say):
    """Say the modes of solve_for_run ``found`` as a table (or their refusal) and write
    -rod_modes_table. Collective."""
    modes, seconds = found
    if isinstance(modes, ModesRefused):
        say(f"modes: refused: {modes}")
        return
    for line in table_lines(modes, seconds):
        say(line)
    if values["rod_modes_table"]:
        write_tables(problem.mesh.comm, modes, values["rod_modes_table"], say)


def table_lines(modes, seconds):
    """The run's lines of the modes: one per mode, lowest first; ``seconds`` the time
    they took."""
    which = "lowest" if modes.band is None else \
        f"in {modes.band[0]:g}-{modes.band[1]:g} Hz (the inertia counts {modes.band[2]})"
    lines = [f"modes: {len(modes.omega2)} {which} about the static state in {seconds:.3g} s "
             "(undamped, no drag; shares of the kinetic energy in plane / out of plane / "
             "axial / torsional)",
             f"  {'mode':>4} {'f (Hz)':>12} {'T (s)':>12} {'modal mass (kg)':>16}  class"]
    for k, (f, T, mass, label, shares) in enumerate(zip(
            modes.frequencies, modes.periods, modes.modal_mass, modes.labels, modes.shares)):
        fractions = " / ".join(f"{share:.2f}" for share in shares)
        lines.append(f"  {k + 1:>4} {f:12.6g} {T:12.6g} {mass:16.6g}  {label} ({fractions})")
    if modes.symmetrised[0]:
        lines.append(f"modes: warning: {symmetrised_text(modes.symmetrised)}")
    if modes.band is None and len(modes.omega2) < modes.asked:
        lines.append(f"modes: warning: {len(modes.omega2)} of the {modes.asked} asked "
                     "converged and verified (none reported is unverified): a larger "
                     "-rod_modes_eps_ncv or -rod_modes_eps_max_it finds the others")
    if modes.band is not None and (modes.slices or modes.band[2] != len(modes.omega2)):
        short = ", ".join(f"{low:.4g}-{high:.4g} Hz" for low, high in modes.slices)
        lines.append(f"modes: warning: {len(modes.omega2)} verified modes, the inertia counts "
                     f"{modes.band[2]}; left short: {short or 'none'}: a larger "
                     "-rod_modes_eps_ncv, or -rod_modes_range split there, finds the "
                     "others (none reported is unverified)")
    elif modes.band is not None:
        lines.append(f"modes: every mode of the band verified (relative residual below "
                     f"{RESIDUAL:g}), as many as the inertia counts")
    return lines


def vertex_curvature(S, S_mid, curvature):
    """The modes' curvature (n, n_e, 3) at the elements' midpoints S_mid (n_e,),
    interpolated linearly in S to the vertices S (n_v,): (n, n_v, 3), 1/m per unit
    largest offset; the end vertices take their element's value. (d1, d2, d3) . omega'
    of the P2 rotations is exact at the midpoints, one-sided at a vertex."""
    count = curvature.shape[0]
    flat = curvature.transpose(0, 2, 1).reshape(-1, S_mid.size)
    values = np.array([np.interp(S, S_mid, row) for row in flat])    # a row per mode
    return values.reshape(count, 3, S.size).transpose(0, 2, 1)


def write_tables(comm, modes, path, say):
    """The modes' table to ``path`` and their shapes (gathered in rank order) to
    shapes_path(path), by rank 0, each as a .partial file renamed when complete.
    Collective."""
    mpi = comm.tompi4py()
    count = len(modes.omega2)
    local = np.concatenate([
        np.broadcast_to(np.arange(1, count + 1)[:, None, None], (count, len(modes.S), 1)),
        np.broadcast_to(modes.S[None, :, None], (count, len(modes.S), 1)),
        modes.offset.reshape(count, len(modes.S), 3),
        modes.rotation.reshape(count, len(modes.S), 3)], axis=2)
    pieces = mpi.gather(local, root=0)
    middles = mpi.gather((modes.S_mid, modes.curvature), root=0)
    error = None
    if mpi.Get_rank() == 0:
        vertices = np.concatenate(pieces, axis=1)
        # a band without modes (-rod_modes_range): the tables' headers alone
        rows = np.zeros((0, len(SHAPE_COLUMNS)))
        if count:
            curvature = vertex_curvature(vertices[0, :, 1],
                                         np.concatenate([m[0] for m in middles]),
                                         np.concatenate([m[1] for m in middles], axis=1))
            rows = np.concatenate([vertices, curvature], axis=2).reshape(-1,
                                                                         len(SHAPE_COLUMNS))
        partial = [f"{name}.{os.getpid()}.partial" for name in (path, shapes_path(path))]
        try:
            with open(partial[0], "w") as table:
                table.write(",".join(TABLE_COLUMNS) + "\n")
                for k in range(count):
                    table.write(",".join(
                        [str(k + 1)] + [f"{v:.10g}" for v in (
                            modes.frequencies[k], modes.periods[k],
                            np.sqrt(max(modes.omega2[k], 0.0)), modes.modal_mass[k])]
                        + [modes.labels[k]] + [f"{v:.6f}" for v in modes.shares[k]]) + "\n")
            np.savetxt(partial[1], rows, delimiter=",", fmt="%.10g",
                       header=",".join(SHAPE_COLUMNS), comments="")
            os.replace(partial[0], path)
            os.replace(partial[1], shapes_path(path))
        except OSError as failure:
            for name in partial:
                if os.path.exists(name):
                    os.remove(name)
            error = f"cannot write -rod_modes_table {path}: {failure.strerror}"
    error = mpi.bcast(error, root=0)
    if error:
        raise RodIOError(error)
    say(f"modes: table {path}, shapes {shapes_path(path)}")
