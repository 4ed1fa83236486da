"""Derived outputs at the mesh vertices: positions, frames, strains, moment, force (§6).

Every array is this rank's owned vertices (or owned elements and P2 nodes for the
restart state);
nothing is gathered. Strains at a vertex average the limits from the elements on
either side (u is discontinuous across elements for P2 directors).
"""

import numpy as np

from petsc_rod.mesh.elements import p2_basis, p2_integrals
from petsc_rod.frames import strains


def vertex_strains(solver):
    """u = (u1, u2, u3) at the owned vertices, (n_owned, 3)."""
    mesh = solver.mesh
    first, end = mesh.elements_around_owned_vertices()
    elements = np.arange(first, end)
    h = mesh.coordinates(elements + 1) - mesh.coordinates(elements)
    ends = np.array([0.0, 1.0])
    values = solver.state.evaluate(elements - mesh.ghost_start, p2_basis(ends, h),
                             p2_integrals(ends, h))
    u = strains(values["directors"], values["derivatives"])       # (ne, 2 ends, 3)
    n_owned = mesh.vertex_end - mesh.vertex_start
    total = np.zeros((n_owned, 3))
    count = np.zeros(n_owned)
    for side in (0, 1):
        vertex = elements + side - mesh.vertex_start
        inside = (vertex >= 0) & (vertex < n_owned)
        total[vertex[inside]] += u[inside, side]
        count[vertex[inside]] += 1
    return total / count[:, None]


def vertex_fields(solver, t):
    """All vertex datasets of the result file (docs/method.md §6; docs/output.md)."""
    mesh, scene = solver.mesh, solver.scene
    r = solver.state.r.owned()
    d1 = solver.state.d1.owned()[:, 0]
    d2 = solver.state.d2.owned()[:, 0]
    d3 = r[:, 1]
    u = vertex_strains(solver)
    k = scene.stiffness
    moment = (k[0] * u[:, :1] * d1 + k[1] * u[:, 1:2] * d2 + k[2] * u[:, 2:] * d3)
    force = solver.end_reaction()[None, :] + scene.load_beyond(mesh.vertex_S, t)
    riser = solver.global_step.riser
    if riser is not None:                   # the drag and the seabed (petsc_rod/riser)
        force += riser.force_beyond(solver.state)
    return {"S": mesh.vertex_S, "r": r[:, 0], "d1": d1, "d2": d2, "d3": d3, "u": u,
            "m": moment, "n": force}


def restart_state(solver):
    """Dofs not in the vertex datasets: the P2 midpoints of d1, d2 per owned element, and
    tau, lambda at the owned P2 nodes."""
    n_local = solver.mesh.n_local_elements
    return {"d1_mid": solver.state.d1.owned()[:n_local, 1], "d2_mid": solver.state.d2.owned()[:n_local, 1],
            "tau": solver.state.tau, "lambda": solver.state.lam}


def set_state(solver, vertex, state):
    """Inverse of vertex_fields + restart_state for owned slices (a restart). The file
    holds r and d3 = r' at the vertices: slope's midpoints are those of the Hermite cubic
    they define (RodState.set_centreline)."""
    n_local = solver.mesh.n_local_elements
    n_owned = vertex["r"].shape[0]
    solver.state.set_centreline(vertex["r"], vertex["d3"])
    for field, name in ((solver.state.d1, "d1"), (solver.state.d2, "d2")):
        values = np.zeros((n_owned, 2, 3))
        values[:, 0] = vertex[name]
        values[:n_local, 1] = state[f"{name}_mid"]
        field.set_owned(values)
    solver.state.tau[:] = state["tau"]
    solver.state.lam[:] = state["lambda"]
    solver.state.remember()

