"""The peak memory of whole processes, the interpreter included, per element, and where it
is reached (docs/performance.md, "Memory for long lines").

    python scripts/benchmark_memory.py [--elements 100000] [--ranks 1]

Two measurements, each a process of its own (a process's peak is its whole life's):

* ``iterations``: 20 iterations of the default driver (SNES Anderson mixing at the depth
  it picks, no Newton steps, no stability test) on the 20 km line of
  scripts/benchmark_scaling.py from the straight start;
* ``run``: ``python -m petsc_rod -options_file options/catenary.opts -rod_elements N``,
  the whole command: a converged default run with its stability test (no result file).

Each prints the peak resident size summed over its ranks (getrusage's ru_maxrss, which
/usr/bin/time -f %M reports too), in MiB and in KiB per element, and a table by phase:
the resident size and the peak so far at the end of each phase (VmRSS, VmHWM; rank 0;
glibc keeps freed memory in the process under Open MPI, so the resident size does not
fall when a phase frees what it made: the table's "used" column is malloc's bytes in
use, mallinfo2). ``--markdown`` prints the rows for the docs.
"""

import argparse
import ctypes
import functools
import importlib
import json
import os
import resource
import subprocess
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")     # as python -m petsc_rod runs

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MIB = 2**20
ITERATIONS = 20

# The phases of each measurement: (label, module, class or None, function) wrapped so
# that the end of each call is a row of the table.
PHASES = {
    "iterations": [("the mesh", "petsc_rod.mesh.mesh", "Mesh", "__init__"),
                   ("the problem (fields, chains, factors)", "petsc_rod.problem.problem",
                    "RodProblem", "__init__"),
                   ("the SNES and its vectors", "petsc_rod.iteration.driver", "UzawaSolver",
                    "__init__"),
                   ("the step's set-up (prepare)", "petsc_rod.problem.problem", "RodProblem",
                    "prepare"),
                   ("the iterations (Anderson's history set up)",
                    "petsc_rod.iteration.driver", "UzawaSolver", "_iterate")],
    "run": [("the mesh", "petsc_rod.mesh.mesh", "Mesh", "__init__"),
            ("the problem (fields, chains, factors)", "petsc_rod.problem.problem",
             "RodProblem", "__init__"),
            ("the SNES and its vectors", "petsc_rod.iteration.driver", "UzawaSolver",
             "__init__"),
            ("the start (the catenary)", "petsc_rod.cli.line_run", "BuiltLine", "start"),
            ("the step's set-up (prepare)", "petsc_rod.problem.problem", "RodProblem",
             "prepare"),
            ("the iterations (Anderson's history set up)", "petsc_rod.iteration.driver",
             "UzawaSolver", "_iterate"),
            ("the SNES's work released", "petsc_rod.iteration.driver", "UzawaSolver",
             "release_work"),
            ("H assembled", "petsc_rod.problem.problem", "RodProblem", "second_variation"),
            ("H's LDL^T (MUMPS)", "petsc_rod.analysis.stability", "StabilityTest",
             "factorise"),
            ("the step's record (strains, energy, outputs)", "petsc_rod.io.outputs", None,
             "step_record"),
            ("destroyed", "petsc_rod.cli.line_run", "BuiltLine", "destroy")],
}


def arguments():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=100000)
    parser.add_argument("--ranks", type=int, default=1)
    parser.add_argument("--only", choices=tuple(PHASES), help="one measurement")
    parser.add_argument("--markdown", action="store_true", help="table rows")
    parser.add_argument("--child", choices=tuple(PHASES), help=argparse.SUPPRESS)
    return parser.parse_args()


class MallInfo(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in (
        "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks",
        "fordblks", "keepcost")]


def malloc_in_use():
    """Bytes malloc has handed out and not had back (glibc's mallinfo2), or None."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallinfo2.restype = MallInfo
        info = libc.mallinfo2()
    except (OSError, AttributeError):
        return None
    return info.uordblks + info.hblkhd


def resident():
    """(VmRSS, VmHWM) of this process, bytes."""
    values = {}
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith(("VmRSS:", "VmHWM:")):
                name, value = line.split(":")
                values[name] = int(value.split()[0]) * 1024
    return values["VmRSS"], values["VmHWM"]


def peak():
    """The peak resident size of this process, bytes (Linux's ru_maxrss is in KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def record(rows, label):
    rss, hwm = resident()
    rows.append((label, rss, hwm, malloc_in_use()))


def watch(rows, phases):
    """Wrap each phase's function so that its end is a row of ``rows``."""
    for label, module, owner, name in phases:
        holder = importlib.import_module(module)
        holder = getattr(holder, owner) if owner else holder
        function = getattr(holder, name)

        def wrapped(*args, _function=function, _label=label, **kwargs):
            try:
                return _function(*args, **kwargs)
            finally:
                record(rows, _label)
        setattr(holder, name, functools.wraps(function)(wrapped))


def iterations(comm, elements):
    """20 default iterations of benchmark_scaling's 20 km line from the straight start."""
    sys.path.insert(0, HERE)
    from benchmark_scaling import scene
    from petsc_rod.iteration.driver import solver_for
    from petsc_rod.iteration.stopping import Settings
    from petsc_rod.mesh.mesh import Mesh

    scale, rod = scene()
    mesh = Mesh(comm, elements, rod.length)
    settings = Settings(asked_penalty=400.0 / scale**2, max_it=ITERATIONS, rtol=0.0,
                        ctol=0.0, adapt_penalty=False, check_stability=False, newton=False)
    solver = solver_for(mesh, rod, settings)
    solver.problem.state.set_straight()
    report = solver.solve_step(0.125)
    assert report.iterations == ITERATIONS, report
    solver.destroy()
    solver.problem.destroy()
    mesh.destroy()


def child(kind, elements):
    """One measurement in this process; rank 0 prints its JSON line."""
    rows = []
    record(rows, "the interpreter")
    if kind == "run":
        sys.argv = [sys.argv[0], "-options_file", os.path.join(ROOT, "options", "catenary.opts"),
                    "-rod_elements", str(elements)]
        import petsc4py
        petsc4py.init(sys.argv)
    else:
        import petsc4py
        petsc4py.init(sys.argv[:1])
    from petsc4py import PETSc
    comm = PETSc.COMM_WORLD
    if kind == "run":
        import petsc_rod.cli.main  # noqa: F401  (what the command imports)
    else:
        import petsc_rod.iteration.driver  # noqa: F401
    record(rows, "PETSc, MPI and the program imported")
    watch(rows, PHASES[kind])
    if kind == "run":
        from petsc_rod.__main__ import main
        code = main()
        assert code == 0, code
    else:
        iterations(comm, elements)
    total = comm.tompi4py().allreduce(peak())
    if comm.getRank() == 0:
        print(json.dumps({"kind": kind, "elements": elements, "ranks": comm.getSize(),
                          "peak": total, "rows": rows}), flush=True)


def measure(kind, elements, ranks):
    command = [sys.executable, os.path.abspath(__file__), "--child", kind, "--elements",
               str(elements)]
    if ranks > 1:
        command = ["mpiexec", "-n", str(ranks)] + command
    done = subprocess.run(command, capture_output=True, text=True, check=False, cwd=ROOT)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode or not lines:
        sys.exit(f"{kind} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    return json.loads(lines[-1])


def report(result, markdown):
    elements, ranks, total = result["elements"], result["ranks"], result["peak"]
    title = {"iterations": f"{ITERATIONS} default iterations, 20 km line, straight start",
             "run": "options/catenary.opts, a converged default run with its stability test"}
    print(f"{result['kind']}: {title[result['kind']]}; {elements} elements on {ranks} "
          f"rank(s): peak {total / MIB:.0f} MiB, {total / elements / 1024:.2f} KiB per "
          "element (all ranks, the interpreter included)")
    if markdown:
        print("| phase (rank 0) | resident (MiB) | peak so far (MiB) | malloc in use (MiB) |\n"
              "|---|---:|---:|---:|")
    for label, rss, hwm, used in result["rows"]:
        used = "" if used is None else f"{used / MIB:.0f}"
        if markdown:
            print(f"| {label} | {rss / MIB:.0f} | {hwm / MIB:.0f} | {used} |")
        else:
            print(f"  {label:48s} resident {rss / MIB:6.0f}  peak {hwm / MIB:6.0f}  "
                  f"in use {used:>6s} MiB")


def main():
    args = arguments()
    if args.child:
        child(args.child, args.elements)
        return
    print("load average before: " + " ".join(open("/proc/loadavg").read().split()[:3]))
    for kind in PHASES:
        if args.only in (None, kind):
            report(measure(kind, args.elements, args.ranks), args.markdown)


if __name__ == "__main__":
    main()
