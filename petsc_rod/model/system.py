"""A system of lines meeting at points and bodies (a floater on its moorings, with
risers; an array of floaters sharing anchors): the typed description the system's
input (a MoorDyn file, the Python API) builds and the coupled solver solves.

A line of a system is a Line of sections of line types (model/line.py) or a
UniformLine, with the attachments along it; each of its two ends is a Connection to a
Point or to a Body by name. The sea (Environment) is shared by every line. Plain values
in SI units, z up, angles in radians; nothing here knows PETSc.
"""

from dataclasses import dataclass, field

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.attachment import Attachment
from petsc_rod.model.line import Line, UniformLine
from petsc_rod.model.names import FIELD_NAMES
from petsc_rod.model.sea import Environment
from petsc_rod.model.system_check import check_system
from petsc_rod.model.values import optional, real, reals

# A point is 'fixed' (an anchor: its position held), 'free' (a connection point in
# equilibrium: a clump weight, a buoy, a joint of two lines) or 'prescribed' (held at a
# position the load case gives: a fairlead on a vessel moved by hand).
POINT_KINDS = ("fixed", "free", "prescribed")
# A line's end at a point or a body is pinned (no moment), clamped (the body's frame
# holds the line's end frame) or a flex joint (a rotational spring, N m/rad).
CONNECTION_KINDS = ("pin", "clamp", "flex")


def _name(owner, value):
    if not isinstance(value, str) or not value or any(c.isspace() for c in value):
        raise RodInputError(f"{owner} {value!r}: a name is one word of text")
    return value


@dataclass(frozen=True)
class Point:
    """A point of the system, named ``name``: ``kind`` in POINT_KINDS; ``position``
    (3,), m, absolute (a free point's: where its equilibrium is sought from); ``mass``
    (kg) in air and displaced ``volume`` (m^3) (a clump weight, a buoy); ``force`` (3,),
    N, a constant external force; ``cda`` = C_d A (m^2), its drag area in a current;
    ``ca`` its added-mass coefficient (the system's modes: added mass ca rho_w volume,
    kg, in every direction). Its dead force is force + (rho_w volume - mass) g e_z."""

    name: str
    kind: str = "fixed"
    position: tuple = (0.0, 0.0, 0.0)
    mass: float = 0.0
    volume: float = 0.0
    force: tuple = (0.0, 0.0, 0.0)
    cda: float = 0.0
    ca: float = 0.0

    def __post_init__(self):
        _name("Point.name", self.name)
        if self.kind not in POINT_KINDS:
            raise RodInputError(f"Point {self.name}: kind {self.kind!r}: use one of "
                                f"{', '.join(POINT_KINDS)}")
        reals(f"Point {self.name}: position", self.position, (3,))
        reals(f"Point {self.name}: force", self.force, (3,))
        for name in ("mass", "volume", "cda", "ca"):
            if real(f"Point {self.name}: {name}", getattr(self, name)) < 0:
                raise RodInputError(f"Point {self.name}: {name} {getattr(self, name)!r}: "
                                    "must not be negative")


def check_inertia(owner, inertia, added_mass):
    """Refuse an inertia (3 or 9 numbers) or an added mass (36) that is not symmetric
    and positive semi-definite: a mass matrix is."""
    for name, value, sizes in (("inertia", inertia, (3, 9)), ("added_mass", added_mass,
                                                               (36,))):
        if value is None:
            continue
        array = reals(f"{owner} {name}", value, sizes)
        matrix = np.diag(array) if array.size == 3 else array.reshape(round(array.size**0.5), -1)
        scale = max(float(np.abs(matrix).max()), np.finfo(float).tiny)
        if (np.abs(matrix - matrix.T).max() > 1e-9 * scale
                or np.linalg.eigvalsh(matrix).min() < -1e-9 * scale):
            raise RodInputError(f"{owner} {name} {value!r}: a mass matrix is symmetric "
                                "and has no negative eigenvalue")


@dataclass(frozen=True)
class Body:
    """A rigid body with 6 degrees of freedom, named ``name``. ``position`` (6,): its
    reference point's x, y, z (m) and its rotation's roll, pitch, yaw (rad; the
    rotation R = R_z(yaw) R_y(pitch) R_x(roll) takes body axes to global ones), where
    its equilibrium is sought from. ``mass`` (kg) at ``cog`` (3,), body axes, m;
    displaced ``volume`` (m^3) with its centre of buoyancy ``cob`` (3,); the waterplane's
    ``waterplane_area`` (m^2) and its second moments ``waterplane_moments`` (Ixx, Iyy),
    m^4, about the reference point's vertical; or ``hydrostatic`` (6, 6) given whole
    (N/m, N, N m/rad about the reference point at its start position, in place of
    the volume's and waterplane's own); ``load`` (6,): a constant external force (N)
    and moment (N m) about the reference point, global axes (wind, current, wave
    drift); ``held`` (6,) bools: the degrees of freedom held at ``position``. For the
    system's modes only (system/body_modes.py): ``inertia``, the mass moments of
    inertia about the cog in body axes, kg m^2: (Ixx, Iyy, Izz) or the whole tensor (9
    numbers; None: none, the rotations then massless but for the mass's own m |cog|^2);
    ``added_mass`` (6, 6): the hydrodynamic added mass about the reference point in body
    axes (kg, kg m, kg m^2; rows and columns x, y, z, roll, pitch, yaw; None: none)."""

    name: str
    position: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    mass: float = 0.0
    cog: tuple = (0.0, 0.0, 0.0)
    volume: float = 0.0
    cob: tuple = (0.0, 0.0, 0.0)
    waterplane_area: float = 0.0
    waterplane_moments: tuple = (0.0, 0.0)
    hydrostatic: tuple = None
    load: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    held: tuple = (False,) * 6
    inertia: tuple = None
    added_mass: tuple = None

    def __post_init__(self):
        _name("Body.name", self.name)
        owner = f"Body {self.name}:"
        reals(f"{owner} position", self.position, (6,))
        reals(f"{owner} load", self.load, (6,))
        for name in ("cog", "cob"):
            reals(f"{owner} {name}", getattr(self, name), (3,))
        reals(f"{owner} waterplane_moments", self.waterplane_moments, (2,))
        optional(f"{owner} hydrostatic", self.hydrostatic, reals, (36,))
        check_inertia(owner, self.inertia, self.added_mass)
        for name in ("mass", "volume", "waterplane_area"):
            if real(f"{owner} {name}", getattr(self, name)) < 0:
                raise RodInputError(f"{owner} {name} {getattr(self, name)!r}: must not be "
                                    "negative")
        held = np.asarray(self.held)
        if held.shape != (6,) or held.dtype != bool:
            raise RodInputError(f"{owner} held {self.held!r}: six bools (x, y, z, roll, "
                                "pitch, yaw)")


@dataclass(frozen=True)
class Connection:
    """Where a line's end is fixed: to the Point or Body named ``to``; ``local`` (3,),
    m, the point in the body's axes (a fairlead; zero on a point); ``kind`` in
    CONNECTION_KINDS, with ``stiffness`` (N m/rad) for a flex joint.

    ``direction`` (3,), body axes, any length but not zero: at a clamp or a flex joint
    on a body, the line's tangent at this end pointing INTO the line from the body (a
    riser hanging down from its hang-off: (0, 0, -1)); a flex joint's neutral axis.
    ``twist`` (rad): at a clamp, the roll of the clamp's d1 about ``direction`` from
    its untwisted place (clamp_frame). None: the line's reference frame (d3 along +x)
    at the body's start pose, as it turns with the body (a flex joint: the line's
    direction in its start shape). A pin holds no frame and takes neither; a flex joint
    holds no roll and takes no twist (System.check)."""

    to: str
    local: tuple = (0.0, 0.0, 0.0)
    kind: str = "pin"
    stiffness: float = None
    direction: tuple = None
    twist: float = None

    def __post_init__(self):
        _name("Connection.to", self.to)
        reals(f"Connection to {self.to}: local", self.local, (3,))
        if self.kind not in CONNECTION_KINDS:
            raise RodInputError(f"Connection to {self.to}: kind {self.kind!r}: use one of "
                                f"{', '.join(CONNECTION_KINDS)}")
        optional(f"Connection to {self.to}: stiffness", self.stiffness, real)
        optional(f"Connection to {self.to}: direction", self.direction, reals, (3,))
        optional(f"Connection to {self.to}: twist", self.twist, real)
        if self.direction is not None and not np.linalg.norm(
                np.asarray(self.direction, dtype=float)) > 0:
            raise RodInputError(f"Connection to {self.to}: direction "
                                f"{tuple(self.direction)}: the zero vector has no direction; "
                                "give the line's tangent into the line, body axes")

    def line_frame(self, at_end):
        """The line's end frame this connection holds, body axes, (3, 3) rows d1, d2,
        d3, or None (no ``direction``): clamp_frame(direction, twist) at the line's
        start (S = 0, d3 into the line); at its end (S = L, ``at_end``), where the
        line's d3 points out of it into the body, that frame turned by pi about its d1,
        rows (d1, -d2, -d3)."""
        if self.direction is None:
            return None
        frame = clamp_frame(self.direction, self.twist or 0.0)
        return frame * np.array([[1.0], [-1.0], [-1.0]]) if at_end else frame


def clamp_frame(direction, twist=0.0):
    """The frame (3, 3), rows d1, d2, d3, of a clamp whose d3 is ``direction`` (3,),
    normalised, turned by ``twist`` (rad) about it; axes those of ``direction``.

    Untwisted, d2 is the axes' +z projected normal to d3 and d1 = d2 x d3: the
    reference frame (rows e_y, e_z, e_x) for d3 = e_x. With d3 = (sin b cos a,
    sin b sin a, cos b) (a the azimuth from +x towards +y, b the declination from +z),
    the rows are d1 = (-sin a, cos a, 0), d2 = (-cos b cos a, -cos b sin a, sin b), also
    for a vertical d3 (a = atan2(y, x) of its zero horizontal part, 0). These are
    OrcaFlex's end axes (E = R_z(a) R_y(b) R_z(gamma), twist = gamma) as d1 = E_y,
    d2 = -E_x, d3 = E_z."""
    d3 = np.asarray(direction, dtype=float)
    d3 = d3 / np.linalg.norm(d3)
    a = np.arctan2(d3[1], d3[0])
    b = np.arctan2(np.hypot(d3[0], d3[1]), d3[2])
    d1 = np.array([-np.sin(a), np.cos(a), 0.0])
    d2 = np.array([-np.cos(b) * np.cos(a), -np.cos(b) * np.sin(a), np.sin(b)])
    c, s = np.cos(twist), np.sin(twist)
    return np.array([c * d1 + s * d2, -s * d1 + c * d2, d3])


@dataclass(frozen=True)
class SystemLine:
    """A line of the system, named ``name``: ``line`` a Line of sections of line types
    or a UniformLine, from ``start`` (S = 0) to ``end`` (S = L), Connections;
    ``attachments`` (Attachment, ...) along it."""

    name: str
    line: object
    start: Connection
    end: Connection
    attachments: tuple = ()

    def __post_init__(self):
        _name("SystemLine.name", self.name)
        if not isinstance(self.line, (Line, UniformLine)):
            raise RodInputError(f"line {self.name}: expected a Line or a UniformLine, not "
                                f"{type(self.line).__name__}")
        for which in ("start", "end"):
            if not isinstance(getattr(self, which), Connection):
                raise RodInputError(f"line {self.name}: {which}: expected a Connection")
        if not all(isinstance(a, Attachment) for a in self.attachments):
            raise RodInputError(f"line {self.name}: attachments: a sequence of Attachment")


@dataclass(frozen=True)
class System:
    """Lines (SystemLine, ...) between points (Point, ...) and bodies (Body, ...) in
    one sea (Environment). Names are unique among points and bodies, and among
    lines."""

    lines: tuple
    points: tuple = ()
    bodies: tuple = ()
    environment: Environment = field(default_factory=Environment)

    def __post_init__(self):
        for name, kind in (("lines", SystemLine), ("points", Point), ("bodies", Body)):
            items = getattr(self, name)
            if isinstance(items, (str, bytes)) or not all(isinstance(i, kind) for i in items):
                raise RodInputError(f"System.{name}: a sequence of {kind.__name__}")
        if not isinstance(self.environment, Environment):
            raise RodInputError("System.environment: expected an Environment")

    def check(self, names=FIELD_NAMES, made_by=None):
        """Raise RodInputError on a system no equilibrium can be sought for
        (system_check.check_system): names, connections, each line's own checks worded
        with ``names`` (names.Names), held points a line cannot span, a line too short
        for its ends where it starts, a point without a line, a body's degree of freedom
        nothing restores; ``made_by``: what moved points or changed lines' lengths, for
        the messages (check_system)."""
        check_system(self, names, made_by)

    def node(self, name):
        """The Point or Body named ``name``."""
        for item in (*self.points, *self.bodies):
            if item.name == name:
                return item
        raise RodInputError(f"no point or body is named {name!r}")
