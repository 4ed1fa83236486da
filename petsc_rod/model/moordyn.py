"""A MoorDyn version 2 input file as a System (model/system.py; docs/systems.md, "MoorDyn
files"): its LINE TYPES, BODIES, POINTS (or a version 1 file's CONNECTION PROPERTIES),
LINES and OPTIONS; what petsc_rod cannot honour (rods, line failures, currents from
files, a tabulated stiffness) is refused in one line naming it.

    system, notes = read_moordyn("MoorDyn.dat")

``notes``: the substitutions made (a bending stiffness for EI = 0, the torsional
stiffness, a depth taken from the anchors, ...), one line each, for the run to say.
"""

import math

import numpy as np

from petsc_rod.errors import RodInputError
from petsc_rod.model.line import Line
from petsc_rod.model.moordyn_types import line_types, number, type_row
from petsc_rod.model.sea import GRAVITY, WATER_DENSITY, Environment
from petsc_rod.model.system import Body, Connection, Point, System, SystemLine
from petsc_rod.model.system_check import rotation, tait_bryan_zyx
from petsc_rod.tables import is_number, read_text

# The longest element petsc_rod meshes a MoorDyn line with (m): a line gets
# max(NumSegs, ceil(length / ELEMENT_LENGTH)) elements, MoorDyn's segments (tens of
# metres) being too long for the rod's bending layers and touchdown.
ELEMENT_LENGTH = 1.0
# Section headers ('---- LINE TYPES ----'), by the words in them, longest match first.
SECTIONS = {"LINE TYPES": "types", "LINE DICTIONARY": "types", "ROD TYPES": "rod types",
            "ROD DICTIONARY": "rod types", "BODIES": "bodies", "BODY LIST": "bodies",
            "BODY PROPERTIES": "bodies", "RODS": "rods", "ROD LIST": "rods",
            "ROD PROPERTIES": "rods", "POINTS": "points", "POINT LIST": "points",
            "POINT PROPERTIES": "points", "CONNECTION PROPERTIES": "points",
            "NODE PROPERTIES": "points", "LINES": "lines", "LINE LIST": "lines",
            "LINE PROPERTIES": "lines", "OPTIONS": "options", "FAILURE": "failure",
            "CONTROL": "control", "EXTERNAL LOADS": "loads", "OUTPUT": "outputs"}
# Sections of a table: two lines (the column names, the units) before the rows.
TABLES = ("types", "rod types", "bodies", "rods", "points", "lines", "failure", "control",
          "loads")
# Options of a static meaning, by their lower-case key.
STATIC_OPTIONS = {"wtrdpth": "depth", "depth": "depth", "wtrdnsty": "rho", "rho": "rho",
                  "rhow": "rho", "g": "g", "gravity": "g", "kbot": "kbot", "kb": "kbot",
                  "frictioncoefficient": "mu", "mu_kt": "mu_kt", "mu_ka": "mu_ka"}
# Options of the dynamics (time stepping, damping, the initial condition's relaxation,
# outputs, waves, which have no mean), accepted and ignored.
DYNAMIC_OPTIONS = ("echo", "writelog", "dtm", "cfl", "tscheme", "cbot", "cb", "dtic",
                   "tmaxic",
                   "cdscaleic", "threshic", "wavekin", "dtwave", "wavekin_rampt",
                   "unifycurrentgrid", "writeunits", "fricdamp", "statdynfricscale",
                   "dtout", "icgendynamic", "disableoutput", "disableouttime", "mc", "cv",
                   "inertialf", "inertialf_rampt", "outswitch")
POINT_KINDS = {"fixed": "fixed", "fix": "fixed", "anchor": "fixed", "free": "free",
               "connect": "free", "con": "free", "point": "free", "coupled": "prescribed",
               "vessel": "prescribed", "ves": "prescribed", "cpld": "prescribed"}
# A body's attachment: the degrees of freedom it holds (coupled: held where the load
# case puts it; pinned: its translations only).
BODY_HELD = {"fixed": (True,) * 6, "fix": (True,) * 6, "coupled": (True,) * 6,
             "vessel": (True,) * 6, "ves": (True,) * 6, "cpld": (True,) * 6,
             "free": (False,) * 6, "coupledpinned": (True,) * 3 + (False,) * 3,
             "cpldpin": (True,) * 3 + (False,) * 3}


def read_moordyn(path, element_length=ELEMENT_LENGTH):
    """(System, notes) of the MoorDyn version 2 file ``path`` (checked: System.check);
    ``element_length`` (m) the longest element of a line (ELEMENT_LENGTH)."""
    return parse_moordyn(read_text(path, "MoorDyn file"), str(path), element_length)


def split(text, path):
    """{section: [(line number, tokens), ...]} of the file's text: a table's rows after
    its two header lines, the options' rows; comments (after !, # or %) and blank lines
    dropped. RodInputError for an unknown or repeated section header."""
    sections, current, skip = {}, None, 0
    for number_, raw in enumerate(text.splitlines(), 1):
        stripped = raw.strip()
        if stripped.startswith("--"):
            title = " ".join(stripped.strip("-").split()).upper()
            if "MOORDYN" in title or "NEED THIS LINE" in title or not title:
                current = None              # the file's title line, or its last line
                continue
            key = next((SECTIONS[k] for k in sorted(SECTIONS, key=len, reverse=True)
                        if k in title), None)
            if key is None:
                raise RodInputError(f"{path}:{number_}: unknown section {title!r}; a "
                                    "MoorDyn version 2 file has LINE TYPES, ROD TYPES, "
                                    "BODIES, RODS, POINTS, LINES, OPTIONS, OUTPUTS")
            if key in sections:
                raise RodInputError(f"{path}:{number_}: a second {title} section")
            sections[key], current, skip = [], key, 2 if key in TABLES else 0
            continue
        if current is None or current == "outputs":
            continue
        if skip and stripped:
            skip -= 1                                     # the column names, the units
            continue
        data = uncommented(stripped).split()
        if data:
            sections[current].append((number_, data))
    return sections


def uncommented(text):
    """``text`` before its first comment character (!, # or %), MoorDyn's."""
    cuts = [k for k in (text.find(c) for c in "!#%") if k >= 0]
    return text[:min(cuts)] if cuts else text


def parse_moordyn(text, path="<MoorDyn text>", element_length=ELEMENT_LENGTH):
    """(System, notes) of a MoorDyn version 2 file's ``text`` (read_moordyn); ``path``
    names it in the messages."""
    sections = split(text, path)
    for key, title in (("types", "LINE TYPES"), ("lines", "LINES")):
        if key not in sections:
            raise RodInputError(f"{path}: no {title} section (a header line such as "
                                f"'---------- {title} ----------' before its table)")
    refuse_unhonoured(sections, path)
    sea, notes = options(sections.get("options", []), path)
    if sections.get("control"):
        notes.append("CONTROL: the lines' length control is a time history's; the lines "
                     "keep their unstretched lengths")
    bodies = body_rows(sections.get("bodies", []), path)
    notes.extend(f"body {name}: CdA {fields['cda']:g} m^2 not read (a body takes no drag "
                 "in a current: give that force as a load on the body)"
                 for name, fields in bodies.items() if fields["cda"])
    points, attached = point_rows(sections.get("points", []), bodies, path)
    apply_loads(sections.get("loads", []), points, bodies, path)
    depth = sea["depth"]
    if depth is None:
        fixed = [p["position"][2] for p in points.values() if p["kind"] == "fixed"]
        depth = -min(fixed) if fixed else None
        if depth is not None:
            notes.append(f"no water depth (WtrDpth) in the file: the seabed is at the "
                         f"deepest anchor, z = {-depth:g} m")
    rows = {}
    for line, row in sections["types"]:
        if row[0] in rows:
            raise RodInputError(f"{path}:{line}: LINE TYPES: a second line type {row[0]}")
        rows[row[0]] = type_row(row, f"{path}:{line}")
    lines, uses = line_rows(sections["lines"], rows, attached, element_length, path)
    types, type_notes = line_types(rows.values(), uses, depth, sea["rho"], sea["g"], path)
    notes[:0] = type_notes
    environment = environment_of(sea, depth, types, notes)
    system = System(
        lines=tuple(SystemLine(name, Line([(types[kind], length, count)]), start, end)
                    for name, kind, length, count, start, end in lines),
        points=tuple(Point(name, p["kind"], p["position"], p["mass"], p["volume"],
                           p["force"], p["cda"], p["ca"]) for name, p in points.items()),
        bodies=tuple(Body(name, **body_fields(fields, sea["rho"]))
                     for name, fields in bodies.items()),
        environment=environment)
    system.check()
    return system, tuple(notes)


def refuse_unhonoured(sections, path):
    """Refuse what a static equilibrium of lines, points and bodies cannot honour: rods,
    line failures."""
    for key, what in (("rods", "RODS: rods (rigid cylinders) are not modelled; replace a "
                               "rod by a body, or a line of a stiff line type"),
                      ("failure", "FAILURE: line failures are events of a time history, "
                                  "not of a static equilibrium; drop the section")):
        if sections.get(key):
            line = sections[key][0][0]
            raise RodInputError(f"{path}:{line}: {what}")


def options(rows, path):
    """The static options {depth, rho, g, kbot, mu, mu_kt, mu_ka} (None: not given; rho
    and g petsc_rod's defaults) and the notes of those ignored."""
    found = dict(depth=None, rho=WATER_DENSITY, g=GRAVITY, kbot=None, mu=None, mu_kt=None,
                 mu_ka=None)
    ignored = []
    for line, data in rows:
        if len(data) < 2:
            raise RodInputError(f"{path}:{line}: OPTIONS: a row is a value and a key "
                                f"('320 WtrDpth'), not {' '.join(data)!r}")
        value, key = data[0], data[1].lower()
        if key in ("currents", "waterkin", "seafloorfile") and value not in ("0", '""', "''"):
            raise RodInputError(
                f"{path}:{line}: OPTIONS: {data[1]} {value}: a current or a seabed read "
                "from MoorDyn's grid files is not read; give the run its current and "
                "seabed profile (the command line's current and seabed profile options, "
                "the API's Environment), or drop the option")
        if key in ("currents", "waterkin", "seafloorfile") or key in DYNAMIC_OPTIONS:
            ignored.append(data[1])
        elif key in STATIC_OPTIONS:
            if value.lower() == "default":          # MoorDyn-F: the glue code's value
                continue
            if key == "wtrdpth" and not is_number(value):
                raise RodInputError(f"{path}:{line}: OPTIONS: WtrDpth {value}: a "
                                    "bathymetry file is not read; give the depth (m)")
            found[STATIC_OPTIONS[key]] = number(f"{path}:{line}: OPTIONS", data[1], value)
            if key == "wtrdpth" and not found["depth"] > 0:
                raise RodInputError(f"{path}:{line}: OPTIONS: WtrDpth {value}: the water "
                                    "depth (m, the seabed at z = -WtrDpth) must be "
                                    "positive")
        else:
            raise RodInputError(
                f"{path}:{line}: OPTIONS: unknown option {data[1]!r}; petsc_rod reads "
                "WtrDpth, WtrDnsty, g, kBot, FrictionCoefficient, MU_KT, MU_KA and ignores "
                "the dynamic ones (dtM, cBot, dtIC, TmaxIC, ...)")
    notes = ([f"options without a static meaning, ignored: {', '.join(ignored)}"]
             if ignored else [])
    return found, notes


def triple(where, column, text):
    """A MoorDyn 'x|y|z' field, or one number v as (0, 0, v) (a CG along z)."""
    parts = text.split("|")
    values = [number(where, column, part) for part in parts]
    if len(values) == 1:
        return (0.0, 0.0, values[0])
    if len(values) != 3:
        raise RodInputError(f"{where}: {column} {text!r}: one number or three, x|y|z")
    return tuple(values)


def moordyn_angles(r0, p0, y0):
    """(roll, pitch, yaw), rad, of a Body (R = R_z(yaw) R_y(pitch) R_x(roll)) turned as
    MoorDyn turns a body given r0, p0, y0 (rad): R = R_x(r0) R_y(p0) R_z(y0), its
    Euler2Quat (rotations about the axes X, then the turned Y, then the turned Z). The
    two orders agree for one angle at a time; MoorPy composes R_z R_y R_x and so places
    a body given two or three angles elsewhere than MoorDyn."""
    turned = rotation(r0, 0.0, 0.0) @ rotation(0.0, p0, 0.0) @ rotation(0.0, 0.0, y0)
    return tuple(float(a) for a in tait_bryan_zyx(turned))


def body_rows(rows, path):
    """{'Body<ID>': Body's fields} of the BODIES rows: ID Attachment X0 Y0 Z0 r0 p0 y0
    (deg) Mass CG* I* Volume CdA* Ca*: I (one number for all three, or Ix|Iy|Iz, about
    the cog, body axes) and Ca (one or three numbers) for the system's modes
    (body_fields); CdA kept for a note only (a body takes no drag: read_moordyn says
    so where it is not 0). Buoyancy acts at the reference point (MoorDyn's)."""
    bodies = {}
    for line, data in rows:
        where = f"{path}:{line}: BODIES: body {data[0]}"
        if len(data) < 12:
            raise RodInputError(f"{where}: {len(data)} columns, a body has 14 (ID "
                                "Attachment X0 Y0 Z0 r0 p0 y0 Mass CG I Volume CdA Ca)")
        held = BODY_HELD.get(data[1].lower())
        if held is None:
            raise RodInputError(f"{where}: attachment {data[1]!r}: use one of "
                                f"{', '.join(BODY_HELD)}")
        place = [number(where, c, v) for c, v in zip(("X0", "Y0", "Z0", "r0", "p0", "y0"),
                                                      data[2:8])]
        inertia = [number(where, "I", v) for v in data[10].split("|")]
        if len(inertia) not in (1, 3):
            raise RodInputError(f"{where}: I {data[10]!r}: one number or three, Ix|Iy|Iz")
        ca = ([number(where, "Ca", v) for v in data[13].split("|")]
              if len(data) > 13 else [0.0])
        if len(ca) not in (1, 3):
            raise RodInputError(f"{where}: Ca {data[13]!r}: one number or three, "
                                "Ca_x|Ca_y|Ca_z (the translations' added mass Ca rho V)")
        bodies[f"Body{int(number(where, 'ID', data[0]))}"] = dict(
            position=tuple(place[:3]) + moordyn_angles(*np.radians(place[3:])),
            mass=number(where, "Mass", data[8]), cog=triple(where, "CG", data[9]),
            volume=number(where, "Volume", data[11]), held=held,
            inertia=np.diag(np.broadcast_to(inertia, 3)).astype(float),
            ca=np.broadcast_to(ca, 3).astype(float),
            cda=number(where, "CdA", data[12]) if len(data) > 12 else 0.0)
    return bodies


def body_fields(fields, rho):
    """A body's Body fields from body_rows' (and add_to_body's): its inertia tensor
    about the cog (None where zero) and the added mass of MoorDyn's Ca, rho V Ca in the
    translations at the reference point (where MoorDyn's buoyancy acts; none in the
    rotations), body axes."""
    fields = dict(fields)
    inertia, ca = fields.pop("inertia"), fields.pop("ca")
    fields.pop("cda", None)
    volume = fields.pop("own_volume", fields["volume"])
    fields["inertia"] = tuple(inertia.ravel().tolist()) if np.any(inertia) else None
    added = np.zeros((6, 6))
    added[:3, :3] = np.diag(rho * volume * ca)
    fields["added_mass"] = tuple(added.ravel().tolist()) if np.any(ca) else None
    return fields


def point_rows(rows, bodies, path):
    """({'Point<ID>': {kind, position, mass, volume, force, cda}} of the fixed, free and
    coupled points, {ID: Connection} of every point (a body's: to the body at its local
    coordinates, its mass and volume added to the body's)."""
    points, attached = {}, {}
    for line, data in rows:
        where = f"{path}:{line}: POINTS: point {data[0]}"
        if len(data) < 8:
            raise RodInputError(f"{where}: {len(data)} columns, a point has 9 (ID "
                                "Attachment X Y Z Mass Volume CdA Ca)")
        ident = str(int(number(where, "ID", data[0])))
        if ident in attached:
            raise RodInputError(f"{where}: a second point {ident}")
        x, y, z, mass, volume, cda = (number(where, c, v) for c, v in zip(
            ("X", "Y", "Z", "Mass", "Volume", "CdA"), data[2:8]))
        word = data[1].lower()
        body = numbered(word, "body")
        turbine = numbered(word, "turbine")
        if body:
            name = f"Body{body}"
            if name not in bodies:
                raise RodInputError(f"{where}: attachment {data[1]}: no body {body} in "
                                    "BODIES")
            add_to_body(bodies[name], np.array([x, y, z]), mass, volume)
            attached[ident] = Connection(name, (x, y, z))
            continue
        kind = "prescribed" if turbine else POINT_KINDS.get(word)
        if kind is None:
            raise RodInputError(f"{where}: attachment {data[1]!r}: use Fixed, Free, "
                                "Coupled (or Anchor, Connect, Vessel) or Body<N>")
        ca = number(where, "Ca", data[8]) if len(data) > 8 else 0.0
        points[f"Point{ident}"] = dict(kind=kind, position=(x, y, z), mass=mass,
                                       volume=volume, force=(0.0, 0.0, 0.0), cda=cda, ca=ca)
        attached[ident] = Connection(f"Point{ident}")
    return points, attached


def numbered(word, stem):
    """N of a word 'stemN' (N a whole number), else None."""
    rest = word[len(stem):]
    return int(rest) if word.startswith(stem) and rest.isdigit() else None


def add_to_body(body, local, mass, volume):
    """Add a point's ``mass`` (kg) and ``volume`` (m^3) at ``local`` (body axes, m) to a
    body's fields: the mass at the combined centre of gravity, its inertia about it
    (parallel axes: the body's inertia moved to the new cog, the point's m |d|^2 I -
    m d d^T), the volume's buoyancy at the combined centre of buoyancy (the body's own
    at its reference point)."""
    body.setdefault("own_volume", body["volume"])
    if mass:
        total = body["mass"] + mass
        cog = (body["mass"] * np.asarray(body["cog"]) + mass * local) / total

        def moved(m, d):
            return m * (d @ d * np.eye(3) - np.outer(d, d))
        body["inertia"] = (body["inertia"] + moved(body["mass"], np.asarray(body["cog"]) - cog)
                           + moved(mass, local - cog))
        body["cog"] = tuple(float(v) for v in cog)
        body["mass"] = total
    if volume:
        total = body["volume"] + volume
        body["cob"] = tuple(float(v) for v in (np.asarray(body.get("cob", np.zeros(3)))
                                               * body["volume"] + volume * local) / total)
        body["volume"] = total


def apply_loads(rows, points, bodies, path):
    """EXTERNAL LOADS rows (ID Object Fext Blin Bquad CSys): a constant force on a point,
    or on a body in global axes (CSys G), added to its load; the damping is dynamic."""
    for line, data in rows:
        where = f"{path}:{line}: EXTERNAL LOADS"
        if len(data) < 3:
            raise RodInputError(f"{where}: a row is ID Object Fext Blin Bquad CSys")
        force = np.asarray(triple(where, "Fext", data[2]) if "|" in data[2]
                           else (number(where, "Fext", data[2]),) * 3)
        target = data[1]
        if target.lower().startswith("body") and target.capitalize() in bodies:
            if len(data) > 5 and data[5].upper() == "L" and np.any(force):
                raise RodInputError(f"{where}: {target}: a force in body axes (CSys L) is "
                                    "not read; give it in global axes (G)")
            body = bodies[target.capitalize()]
            body["load"] = tuple(float(v) for v in np.asarray(body.get("load", np.zeros(6)))
                                 + np.concatenate([force, np.zeros(3)]))
        elif target.lower().startswith("point") and target.capitalize() in points:
            point = points[target.capitalize()]
            point["force"] = tuple(float(v) for v in np.asarray(point["force"]) + force)
        else:
            raise RodInputError(f"{where}: object {target!r}: a load on a Body<N> or a "
                                "Point<N> of the file (rods are not modelled)")


def line_rows(rows, types, attached, element_length, path):
    """The lines (name, type, length m, elements, start, end Connection) of the LINES
    rows (ID LineType AttachA AttachB UnstrLen NumSegs Outputs), and {type: [(length,
    element length), ...]} of the lines of each type."""
    lines, uses = [], {}
    for line, data in rows:
        where = f"{path}:{line}: LINES: line {data[0]}"
        if len(data) < 6:
            raise RodInputError(f"{where}: {len(data)} columns, a line has 7 (ID LineType "
                                "AttachA AttachB UnstrLen NumSegs Outputs)")
        if data[1] not in types:
            raise RodInputError(f"{where}: no line type {data[1]!r} in LINE TYPES "
                                f"({', '.join(types)})")
        ends = []
        for column, ident in (("AttachA", data[2]), ("AttachB", data[3])):
            if ident[:1] in "Rr" and ident[-1:] in "AaBb" and ident[1:-1].isdigit():
                raise RodInputError(f"{where}: {column} {ident}: a rod's end; rods are not "
                                    "modelled")
            key = str(int(ident)) if ident.isdigit() else ident
            if key not in attached:
                raise RodInputError(f"{where}: {column} {ident}: no point {ident} in "
                                    "POINTS")
            ends.append(attached[key])
        length = number(where, "UnstrLen", data[4])
        segments = number(where, "NumSegs", data[5])
        if not length > 0 or segments < 1 or segments != int(segments):
            raise RodInputError(f"{where}: UnstrLen must be positive and NumSegs a whole "
                                "number of at least 1")
        count = max(int(segments), math.ceil(length / element_length))
        lines.append((f"Line{int(number(where, 'ID', data[0]))}", data[1], length, count,
                      *ends))
        uses.setdefault(data[1], []).append((length, length / count))
    return lines, uses


def environment_of(sea, depth, types, notes):
    """The Environment: the seabed at -depth of stiffness kBot (Pa/m, per metre of
    contact width) times the line types' diameter (the largest, where they differ; None:
    petsc_rod's default), friction mu (FrictionCoefficient) or (MU_KA, MU_KT) (axial,
    lateral), the sea surface at z = 0, the water's density and gravity."""
    stiffness = None
    if sea["kbot"] is not None and depth is not None:
        diameters = sorted({kind.od for kind in types.values()})
        stiffness = sea["kbot"] * diameters[-1]
        notes.append(f"kBot {sea['kbot']:g} Pa/m times the line types' diameter "
                     f"{diameters[-1]:g} m{' (the largest)' if len(diameters) > 1 else ''}: "
                     f"seabed stiffness {stiffness:.4g} N/m^2")
    friction = None
    if sea["mu"]:
        friction = sea["mu"]
    elif sea["mu_ka"] or sea["mu_kt"]:
        friction = (sea["mu_ka"] or 0.0, sea["mu_kt"] or 0.0)
    return Environment(seabed=None if depth is None else -depth,
                       seabed_stiffness=stiffness,
                       seabed_friction=friction if depth is not None else None,
                       surface=0.0, water_density=sea["rho"], gravity=sea["g"])
