"""What a result file holds of a problem's state (problem/problem.py): the vertex fields
(positions, frames, strains, moment, force, §6, and what the terms and the reports add:
collect, the one merge of their outputs for the HDF5 file and the CSV table), the
restart state, and a step's attributes (docs/output.md).

Every array is this rank's owned vertices (or owned elements and P2 nodes for the
restart state); nothing is gathered. Strains at a vertex average the limits from the
elements on either side (u is discontinuous across elements for P2 directors).
"""

from dataclasses import dataclass

import numpy as np


def vertex_strains(problem, moments=False):
    """u = (u1, u2, u3) at the owned vertices, (n_owned, 3): the mean of the limits
    from the elements on either side. With ``moments``, also the moment's components
    K_i u_i (n_owned, 3), the mean of the one-sided K u, each with the stiffness of its
    own side (Scene.stiffness_at from the element): where the stiffness jumps at a
    section end the moment is continuous and the strain is not."""
    mesh, scene = problem.mesh, problem.scene
    first, end = mesh.elements_around_owned_vertices()
    elements = np.arange(first, end)
    S, u = problem.end_strains(elements)                            # (ne, 2 ends, 3)
    sided = [u]
    if moments:
        middle = np.broadcast_to(S.mean(axis=1)[:, None], S.shape)
        sided.append(scene.stiffness_at(S, inside=middle) * u)
    n_owned = mesh.vertex_end - mesh.vertex_start
    totals = [np.zeros((n_owned, 3)) for _ in sided]
    count = np.zeros(n_owned)
    for side in (0, 1):
        vertex = elements + side - mesh.vertex_start
        inside = (vertex >= 0) & (vertex < n_owned)
        for total, value in zip(totals, sided):
            total[vertex[inside]] += value[inside, side]
        count[vertex[inside]] += 1
    means = [total / count[:, None] for total in totals]
    return tuple(means) if moments else means[0]


def vertex_fields(problem):
    """The vertex datasets of the result file that every problem has (docs/method.md §6;
    docs/output.md): S, r, d1, d2, d3, u, the moment m and the internal force n
    (RodProblem.internal_force). Collective."""
    mesh, state = problem.mesh, problem.state
    r = state.r.owned()
    d1 = state.d1.owned()[:, 0]
    d2 = state.d2.owned()[:, 0]
    d3 = r[:, 1]
    if problem.scene.uniform_stiffness:
        u = vertex_strains(problem)
        k = problem.scene.stiffness
        moment = (k[0] * u[:, :1] * d1 + k[1] * u[:, 1:2] * d2 + k[2] * u[:, 2:] * d3)
    else:                   # the stiffness of each side (vertex_strains)
        u, ku = vertex_strains(problem, moments=True)
        moment = ku[:, :1] * d1 + ku[:, 1:2] * d2 + ku[:, 2:] * d3
    return {"S": mesh.vertex_S, "r": r[:, 0], "d1": d1, "d2": d2, "d3": d3, "u": u,
            "m": moment, "n": problem.internal_force()}


def restart_state(problem):
    """Dofs not in the vertex datasets: the P2 midpoints of d1, d2 per owned element, and
    tau, lambda at the owned P2 nodes."""
    n_local, state = problem.mesh.n_local_elements, problem.state
    return {"d1_mid": state.d1.owned()[:n_local, 1], "d2_mid": state.d2.owned()[:n_local, 1],
            "tau": state.tau, "lambda": state.lam}


def set_state(problem, vertex, saved):
    """Inverse of vertex_fields + restart_state for owned slices (a restart). The file
    holds r and d3 = r' at the vertices: slope's midpoints are those of the Hermite cubic
    they define (RodState.set_centreline)."""
    n_local, state = problem.mesh.n_local_elements, problem.state
    n_owned = vertex["r"].shape[0]
    state.set_centreline(vertex["r"], vertex["d3"])
    for field, name in ((state.d1, "d1"), (state.d2, "d2")):
        values = np.zeros((n_owned, 2, 3))
        values[:, 0] = vertex[name]
        values[:n_local, 1] = saved[f"{name}_mid"]
        field.set_owned(values)
    state.tau[:] = saved["tau"]
    state.lam[:] = saved["lambda"]
    state.remember()


@dataclass
class Collected:
    """The outputs of a problem's terms and reports merged (collect): the vertex fields
    with their datasets, their attributes, their phrases for the step line, and the
    units ({dataset: unit}, {attribute: unit}) of what they write (RodProblem.units)."""

    vertex: dict
    attributes: dict
    texts: list
    units: tuple


def collect(problem, vertex=None):
    """The Collected of the problem's state: the vertex fields ``vertex`` (vertex_fields
    when None) updated with the terms' and then the reports' datasets, every output
    computed from the fields alone before any is merged; r absolute (the solver's frame
    has its origin at the start, Scene.start_position, docs/method.md §5; the terms and
    reports translate their own). Collective."""
    vertex = vertex_fields(problem) if vertex is None else vertex
    attributes, texts = {}, []
    for output in problem.outputs(vertex):
        vertex.update(output.datasets)
        attributes.update(output.attributes)
        if output.text:
            texts.append(output.text)
    vertex["r"] = vertex["r"] + problem.scene.start_position
    return Collected(vertex, attributes, texts, problem.units())


def stability_code(report):
    """The file's ``stable``: 1 a local minimiser, 0 a saddle, -1 not checked."""
    return -1 if report.stable is None else int(report.stable)


@dataclass
class StepRecord:
    """What a step leaves (step_record): the vertex datasets (the terms' and reports'
    included), the group's attributes, the terms' and reports' phrases for the step
    line, u3(0) (1/m) for it, and the units of what the terms and reports wrote
    (Collected.units)."""

    vertex: dict
    attributes: dict
    texts: list
    u3_start: float
    units: tuple

    @property
    def energy(self):
        return self.attributes["energy"]


def step_record(problem, report, t, **common):
    """The StepRecord of the problem's state after a step at load factor t with its
    stopping.StepReport, with the attributes ``common`` to the run so far (wall time,
    options, halvings, totals). Collective."""
    mesh = problem.mesh
    vertex = vertex_fields(problem)
    u3_start = mesh.global_sum(vertex["u"][0, 2] if mesh.on_lower_boundary else 0.0)
    attributes = {"converged": int(report.converged),
                  "stop_reason": report.reason or "converged", "iterations": report.iterations,
                  "constraint_residual": report.constraint_residual,
                  "change": report.change, "stable": stability_code(report),
                  "newton_steps": report.newton_steps,
                  "energy": problem.energy(), "ranks": mesh.comm.getSize(),
                  "load_factor": t, "penalty": problem.penalty, **common}
    if report.link is not None:
        attributes.update(twist_turns=report.link[0], writhe_turns=report.link[1])
    collected = collect(problem, vertex)
    attributes.update(collected.attributes)
    return StepRecord(collected.vertex, attributes, collected.texts, u3_start,
                      collected.units)

