"""The shape of the package (docs/design.md), read from the code's own imports and
strings with ``ast``: no loop between folders, the core never imports the environment,
the reports or the terms of an application (its terms come in a list,
problem/build.py), nothing below the front ends imports one, and the algorithm layer
never names a command-line option (cli/ says what to change)."""

import ast
import os
from collections import defaultdict

from helpers import REPO_ROOT

PACKAGE = os.path.join(REPO_ROOT, "petsc_rod")
# Folders and modules that make up the core of the method, which must work with any
# list of terms and so never import an application's (APPLICATION).
CORE = ("global_step", "iteration", "analysis", "local_step", "mesh", "physics/term.py",
        "physics/dead_loads.py", "physics/stretch.py", "physics/flex_joint.py",
        "physics/point_loads.py", "problem/problem.py", "problem/state.py",
        "io/outputs.py")
# What only some scenes build (problem/build.py): the sea and the seabed, the reports,
# and the terms of the seabed, the current and the sea surface (dotted below petsc_rod).
APPLICATION = ("environment", "quantities", "physics.nodal_load", "physics.seabed",
               "physics.drag", "physics.surface", "physics.friction", "physics.slope_load")
# The front ends, which drive the solver and which nothing below them imports; system/
# (a system of lines solved together) drives lines as api/ does, at api/'s level.
FRONT_ENDS = ("cli", "api", "sweep", "report", "plots", "figures", "__main__", "system",
              "cli_system")
BELOW_FRONT_ENDS = CORE + ("physics", "environment", "quantities", "problem", "scenes", "io",
                           "frames.py", "errors.py", "tables.py", "resources.py", "model",
                           "compile.py")
# The algorithm layer and the model, whose messages must not name -rod_* options (the
# model names its fields through model/names.py, the command line gives its options').
ALGORITHM = ("iteration", "analysis", "problem", "physics", "global_step", "model",
             "system")


def modules():
    """{path relative to petsc_rod/: ast.Module} of every module of the package."""
    found = {}
    for folder, _, files in os.walk(PACKAGE):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as source:
                    found[os.path.relpath(path, PACKAGE)] = ast.parse(source.read())
    return found


def imported(tree):
    """The petsc_rod modules a module imports, dotted below petsc_rod."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.startswith("petsc_rod."):
                base = node.module.removeprefix("petsc_rod.")
                names.add(base)
                names.update(f"{base}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            names.update(alias.name.removeprefix("petsc_rod.") for alias in node.names
                         if alias.name.startswith("petsc_rod."))
    return names


def folder_of(path):
    """The top-level folder of a module (or the module itself at the top)."""
    return path.split(os.sep)[0].removesuffix(".py")


def test_no_loop_between_folders():
    graph = defaultdict(set)
    for path, tree in modules().items():
        here = folder_of(path)
        for name in imported(tree):
            there = name.split(".")[0]
            known = (os.path.isdir(os.path.join(PACKAGE, there))
                     or os.path.isfile(os.path.join(PACKAGE, f"{there}.py")))
            if known and there != here:
                graph[here].add(there)
    visiting, done = set(), set()

    def visit(node, trail):
        assert node not in visiting, f"a loop between folders: {' -> '.join(trail + [node])}"
        if node in done:
            return
        visiting.add(node)
        for child in sorted(graph[node]):
            visit(child, trail + [node])
        visiting.discard(node)
        done.add(node)

    for node in sorted(graph):
        visit(node, [])
    assert graph["problem"] and graph["iteration"]       # the graph was read


def test_no_two_modules_of_a_folder_import_each_other():
    """A pair of modules that import each other (at the top or inside a function) is a
    circle inside a folder: what both need belongs in one of them or below them."""
    dotted = {path.removesuffix(".py").replace(os.sep, "."): tree
              for path, tree in modules().items()}
    uses = {name: {other for other in imported(tree) if other in dotted and other != name}
            for name, tree in dotted.items()}
    circles = sorted((a, b) for a in uses for b in uses[a] if a < b and a in uses[b])
    assert not circles, f"modules that import each other: {circles}"
    assert uses["cli.main"]                                 # the imports were read


def test_the_core_never_imports_an_application():
    for path, tree in modules().items():
        if path.startswith(CORE):
            found = sorted(name for name in imported(tree)
                           if name.split(".")[0] in APPLICATION
                           or ".".join(name.split(".")[:2]) in APPLICATION)
            assert not found, f"{path} imports {found}: a term belongs in problem/build.py"


def test_nothing_below_the_front_ends_imports_one():
    seen = 0
    for path, tree in modules().items():
        if path.startswith(BELOW_FRONT_ENDS):
            seen += 1
            found = sorted(name for name in imported(tree)
                           if name.split(".")[0] in FRONT_ENDS)
            assert not found, f"{path} imports the front end {found}"
    assert seen > 50                    # the modules were read


def test_the_system_solver_imports_no_front_end():
    """system/ sits beside api/: the command line and the API use it, it uses neither
    (the command line's builders that api/run.py uses as well: the next test)."""
    others = set(FRONT_ENDS) - {"system", "cli"}
    above = {path: sorted(name for name in imported(tree) if name.split(".")[0] in others)
             for path, tree in modules().items() if folder_of(path) == "system"}
    assert len(above) >= 3                                  # the folder was read
    assert not any(above.values()), f"system/ imports a front end: {above}"


def test_the_result_file_knows_no_term_and_no_report():
    """io/results.py writes the units the terms and reports give it (RodProblem.units),
    so it imports none of them."""
    found = sorted(name for name in imported(modules()[os.path.join("io", "results.py")])
                   if name.split(".")[0] in ("physics", "quantities", "environment"))
    assert not found, f"io/results.py imports {found}"


def test_reports_are_not_terms_and_own_their_units():
    from petsc_rod.physics.term import Term
    from petsc_rod.problem import build
    from petsc_rod.quantities.report import Report
    reports = [value for value in vars(build).values()
               if isinstance(value, type) and issubclass(value, Report)]
    assert len(reports) == 7          # with module_bends.ModuleBends
    for report in reports:
        assert not issubclass(report, Term), report
        assert report.name and report.attribute_units, report


def test_a_report_that_is_a_function_and_its_units_is_one_function_report():
    """The reports that only wrap a function and a units table are FunctionReports
    (quantities/report.py): outputs(problem, vertex) is the function of (problem,
    vertex, *the arguments it was made with); ModuleBends, with state of its own, is a
    plain Report."""
    from petsc_rod.quantities import (line_results, module_bends, pressures, regions,
                                      riser_numbers, section_numbers, stresses)
    from petsc_rod.quantities.report import FunctionReport
    shells = {riser_numbers.RiserNumbers: riser_numbers.riser_report,
              regions.LineRegions: regions.region_report,
              pressures.PipePressures: pressures.pressure_report,
              stresses.PipeStresses: stresses.stress_report,
              section_numbers.SectionNumbers: section_numbers.section_numbers,
              line_results.LineResults: line_results.line_report}
    for report, function in shells.items():
        assert issubclass(report, FunctionReport) and report.report is function, report
    assert not issubclass(module_bends.ModuleBends, FunctionReport)

    class Echo(FunctionReport):
        name, report = "echo", lambda problem, vertex, *more: (problem, vertex, more)

    assert Echo("a", 2).outputs("problem", "vertex") == ("problem", "vertex", ("a", 2))


def docstrings(tree):
    """The ids of the string nodes that are docstrings."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                found.add(id(first.value))
    return found


def test_the_algorithm_layer_names_no_command_line_option():
    for path, tree in modules().items():
        if not path.startswith(ALGORITHM):
            continue
        skip = docstrings(tree)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and id(node) not in skip):
                assert "-rod_" not in node.value, (f"{path}:{node.lineno} names an option: "
                                                   f"{node.value!r}")


# What the model (petsc_rod/model) may import: numpy, the standard library, and of the
# package only the errors, the tables and itself; never PETSc or a front end.
MODEL_MAY_IMPORT = ("model", "errors", "tables")


def external_imports(tree):
    """The top-level names of the modules outside petsc_rod a module imports."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
        elif isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
    return names - {"petsc_rod"}


def test_the_model_imports_no_petsc_and_no_front_end():
    found = 0
    for path, tree in modules().items():
        if folder_of(path) != "model":
            continue
        found += 1
        inside = sorted(name for name in imported(tree)
                        if name.split(".")[0] not in MODEL_MAY_IMPORT)
        assert not inside, f"{path} imports {inside}: the model knows only itself"
        outside = sorted(external_imports(tree) - {"numpy", "dataclasses", "math"})
        assert not outside, f"{path} imports {outside}: the model needs numpy alone"
    assert found >= 6                                       # the folder was read



def test_a_scene_is_made_whole_by_its_constructor():
    """The seabed, the current and the pressures were set on the Scene after it was made
    (cli/scene_options.py), the attachments' names by the API (api/run.py): now the
    compile (compile.py) gives every field to the constructor, and no module sets a
    field of a made scene."""
    for path, tree in modules().items():
        if path == os.path.join("scenes", "scene.py"):
            continue
        for node in ast.walk(tree):
            targets = (node.targets if isinstance(node, ast.Assign) else
                       [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign))
                       else [])
            for target in targets:
                for part in ast.walk(target):
                    assert not (isinstance(part, ast.Attribute)
                                and isinstance(part.value, ast.Name)
                                and part.value.id == "scene"), \
                        f"{path}:{node.lineno} sets scene.{part.attr} on a made Scene"


# The layer of a system's components (petsc_rod/system), at the level of the front
# ends' helpers: it drives its lines as the Python API does, on the one run path of a
# line, so of the front ends it imports cli/line_run.py alone (plan_line, BuiltLine,
# values_of), never the options, the scene options or the session behind it.
SYSTEM_NOT = ("api", "sweep", "report", "plots", "figures", "__main__", "cli_system")


def test_the_system_layer_imports_only_the_run_path():
    found = 0
    for path, tree in modules().items():
        if folder_of(path) != "system":
            continue
        found += 1
        names = imported(tree)
        front = sorted(name for name in names if name.split(".")[0] in SYSTEM_NOT)
        assert not front, f"{path} imports the front end {front}"
        cli = sorted(name for name in names if name.split(".")[0] == "cli"
                     and name != "cli.line_run" and not name.startswith("cli.line_run."))
        assert not cli, f"{path} imports {cli}: only the run path, cli/line_run.py"
    assert found >= 2                                       # the folder was read
