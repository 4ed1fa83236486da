"""An attachment: a clump weight, a buoyancy module or a point force on the line."""

from dataclasses import dataclass

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.values import real, reals


@dataclass(frozen=True)
class Attachment:
    """A clump weight, a buoyancy module or a point force at arc length ``S`` (m):
    ``mass`` in air (kg), displaced ``volume`` (m^3), ``force`` (3,), N, drag area
    ``cda`` = C_d A (m^2) in a current, ``name`` a label (None: 'point k'). Its dead
    force is force + (rho_w volume - mass) g e_z (attachment_forces); ``weighed``: the
    ``force`` is that whole dead force already (a result file's table keeps the forces,
    not the masses), the ``volume`` kept for its buoyancy above the sea surface."""

    S: float
    mass: float = 0.0
    volume: float = 0.0
    force: tuple = (0.0, 0.0, 0.0)
    cda: float = 0.0
    name: str = None
    weighed: bool = False

    def __post_init__(self):
        for name in ("S", "mass", "volume", "cda"):
            real(f"Attachment.{name}", getattr(self, name))
        # the dead force of a heavy attachment may exceed the bound of its numbers: the
        # applied force's check names it (model/derived.check_applied_forces)
        reals("Attachment.force", self.force, (3,), np.inf)
        if self.name is not None and (not isinstance(self.name, str) or "\n" in self.name):
            raise RodInputError(f"Attachment.name {self.name!r}: a name is one line of text")


def attachment_forces(columns, density, gravity):
    """P = (fx, fy, fz) + (rho_w V - m) g e_z, N, (n_p, 3), from the numeric
    ``columns`` {name: (n_p,)} of s, mass, volume, fx, fy, fz (absent ones zero)."""
    n = len(columns["s"])
    get = lambda name: np.asarray(columns.get(name, np.zeros(n)), dtype=float)  # noqa: E731
    force = np.stack([get("fx"), get("fy"), get("fz")], axis=-1)
    force[:, 2] += (density * get("volume") - get("mass")) * gravity
    return force


def dead_forces(attachments, density, gravity):
    """The dead force of each attachment, (n_p, 3), N, in water of ``density`` (kg/m^3)
    under ``gravity`` (m/s^2): attachment_forces, or its ``force`` where it is weighed."""
    columns = attachment_columns(attachments)
    forces = attachment_forces(columns, density, gravity)
    weighed = np.array([a.weighed for a in attachments], dtype=bool)
    forces[weighed] = np.array([a.force for a in attachments], dtype=float)[weighed]
    return forces


def attachment_columns(attachments):
    """The columns {s, mass, volume, fx, fy, fz, cda} (n_p,) of ``attachments``."""
    force = np.array([a.force for a in attachments], dtype=float).reshape(-1, 3)
    return {"s": np.array([a.S for a in attachments], dtype=float),
            "mass": np.array([a.mass for a in attachments], dtype=float),
            "volume": np.array([a.volume for a in attachments], dtype=float),
            "fx": force[:, 0], "fy": force[:, 1], "fz": force[:, 2],
            "cda": np.array([a.cda for a in attachments], dtype=float)}
