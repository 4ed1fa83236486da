"""How a refusal names what the caller gave: every check of the model words its message
with ``names[key]``, the key a field of the model as the command line spells its option
without ``-rod_`` ('end_position', 'seabed_stiffness', ...). The model's own names
(FIELD_NAMES: 'Model.end.position') are the default; the command line passes its
option names (cli/scene_options.OPTION_NAMES: '-rod_end_position')."""


class Names:
    """``names[key]``: ``table[key]``, else ``fallback(key)``."""

    def __init__(self, table, fallback):
        self.table, self.fallback = dict(table), fallback

    def __getitem__(self, key):
        return self.table[key] if key in self.table else self.fallback(key)


_ENDS = {f"{end}{option}": f"Model.{end}{field}" for end in ("start", "end")
         for option, field in (("", ""), ("_position", ".position"),
                               ("_rotational_stiffness", ".stiffness"),
                               ("_joint_axis", ".axis"), ("_force", ".force"),
                               ("_frame", ".frame"), ("_twist", ".twist"))}
FIELD_NAMES = Names({
    "sections": "Line.sections", "line_types": "the LineTypes",
    "elements": "Line.element_length", "length": "Line.length",
    "contents_density": "Line.contents_density",
    "internal_pressure": "Line.internal_pressure", "design_factor": "Line.design_factor",
    "stiffness": "UniformLine.stiffness", "axial_stiffness": "UniformLine.axial_stiffness",
    "load": "UniformLine.load", "load_breaks": "UniformLine.load_breaks",
    "drag": "UniformLine.drag",
    "point_loads": "Model.attachments", "point_load": "Model.attachments",
    "current": "Environment.current", "current_profile": "Environment.current",
    "sea_surface": "Environment.surface", **_ENDS,
    **{name: f"Environment.{name}" for name in (
        "seabed", "seabed_stiffness", "seabed_friction", "seabed_friction_stiffness",
        "seabed_slope", "seabed_direction", "seabed_origin", "seabed_profile",
        "water_density", "gravity")}}, lambda key: f"Model.{key}")
