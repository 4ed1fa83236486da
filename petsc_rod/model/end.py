"""One end of a line."""

from dataclasses import dataclass

from petsc_rod.errors import RodInputError
from petsc_rod.model.values import optional, real, reals

KINDS = ("pin", "clamp", "free")


@dataclass(frozen=True)
class End:
    """One end of the line: ``kind`` 'pin' (held in position: an anchor, a hang-off),
    'clamp' (position and frame) or 'free'; ``position`` (3,), m, absolute, z up (a
    held end's; None: the start at the origin, the end the start + (L, 0, 0)); a flex
    joint at a pin of rotational stiffness ``stiffness`` (N m/rad) about ``axis`` (3,)
    (None: the line's direction at that end in its start shape,
    scenes/starts.start_direction; docs/riser.md §8); ``force`` (3,), N, a dead force
    at a free end; ``frame`` (9,) the rows d1, d2, d3 of a clamped end's frame (None:
    e_y, e_z, e_x) and ``twist`` (rad) an extra roll of a clamped end S = L about its d3. A field left None is not given: a
    field given where the kind has no use for it is refused (Model.check)."""

    kind: str = "pin"
    position: tuple = None
    stiffness: float = None
    axis: tuple = None
    force: tuple = None
    frame: tuple = None
    twist: float = None

    def __post_init__(self):
        if not isinstance(self.kind, str):      # its value: Model.check
            raise RodInputError(f"End.kind {self.kind!r}: use one of {', '.join(KINDS)}")
        optional("End.stiffness", self.stiffness, real)
        optional("End.twist", self.twist, real)
        for name in ("position", "axis", "force"):
            optional(f"End.{name}", getattr(self, name), reals, (3,))
        optional("End.frame", self.frame, reals, (9,))

    @classmethod
    def anchor(cls, position):
        """A pinned end at ``position`` (m), on the seabed or above it."""
        return cls("pin", tuple(position))

    @classmethod
    def hang_off(cls, position, flex_joint=0.0, axis=None):
        """The vessel's end at ``position`` (m): a pin, or a flex joint of stiffness
        ``flex_joint`` (N m/rad) about ``axis`` (default: the line's direction at the
        hang-off in its catenary, where the joint is unloaded: scenes/starts.start_direction)."""
        return cls("pin", tuple(position), flex_joint or None,
                   None if axis is None else tuple(axis))
