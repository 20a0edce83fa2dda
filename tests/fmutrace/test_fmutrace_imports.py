"""fmutrace's modules form layers without cycles (click's test_imports.py
is the model): every import of the package's sources, those inside
functions included, read from their syntax trees; each module placed in
a layer, and importing only from its own layer or lower ones; the
readers (recordings/) at the bottom. A fresh interpreter shows what
`import fmutrace` loads: no POSIX-only module, none of the heavy packages
that only a campaign on Dask, a plot or an MDF file needs."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from support.fmu_driver import BUILD_DIR

PACKAGE = Path(__file__).resolve().parents[2] / "fmutrace" / "src" / "fmutrace"

# lowest first; a module imports from its own layer or the ones before it
LAYERS = [
    ("base", {"fmutrace._errors", "fmutrace._names", "fmutrace._progress", "fmutrace._native", "fmutrace._reading"}),
    ("readers", {"fmutrace._traces", "fmutrace.recordings", "fmutrace.recordings.*"}),
    (
        "model",
        {
            "fmutrace._fmu",
            "fmutrace._comparison",
            "fmutrace._comparison_verdicts",
            "fmutrace._comparison_modes",
            "fmutrace._comparison_tube",
            "fmutrace._comparison_discrete",
            "fmutrace._comparison_criteria",
            "fmutrace._fmpy",
            "fmutrace._outcome",
        },
    ),
    (
        "runs",
        {
            "fmutrace._runner",
            "fmutrace._simulation",
            "fmutrace._cases",
            "fmutrace._recorded",
            "fmutrace._plot",
            "fmutrace._report",
            "fmutrace._journal",
            "fmutrace._lsref",
        },
    ),
    ("one case", {"fmutrace._pipeline", "fmutrace._recording", "fmutrace._worker"}),
    ("where cases run", {"fmutrace._workers", "fmutrace._executors"}),
    ("campaign", {"fmutrace._campaign"}),
    ("checks", {"fmutrace._check"}),
    ("interfaces", {"fmutrace", "fmutrace.cli", "fmutrace.__main__", "fmutrace.pytest_plugin"}),
]
# the readers' package; the pytest plugin (named by the package's pytest11 entry point)
PUBLIC = {"fmutrace", "fmutrace.cli", "fmutrace.__main__", "fmutrace.recordings", "fmutrace.pytest_plugin"}
POSIX_ONLY = {"fcntl", "termios", "pwd", "grp", "resource", "posix", "tty", "pty"}
LOADED_ON_USE = ("dask", "distributed", "matplotlib", "asammdf", "pandas")  # campaigns on Dask, plots, MDF4


def module_names():
    names = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = ("fmutrace",) + path.relative_to(PACKAGE).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        names[".".join(parts)] = path
    return names


def imports(name, path, modules):
    """{(imported module, 'module' or 'function')}: the fmutrace modules
    and the top-level names of the others that the module imports."""
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node, where in _import_nodes(ast.parse(path.read_text(), str(path)), "module"):
        if isinstance(node, ast.Import):
            found |= {(alias.name, where) for alias in node.names}
        else:
            base = node.module
            if node.level:
                base = ".".join(package[: len(package) - node.level + 1] + ([node.module] if node.module else []))
            for alias in node.names:
                full = f"{base}.{alias.name}"
                found.add((full if full in modules else base, where))
    return found


def _import_nodes(node, where):
    """(import statement, where) of every import under node: 'module',
    'module, by platform' (under an if at module level) or 'function'."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.Import, ast.ImportFrom)):
            yield child, where
        inside = (
            "function"
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            else "module, by platform"
            if isinstance(child, ast.If) and where == "module"
            else where
        )
        yield from _import_nodes(child, inside)


def graph():
    modules = module_names()
    return {name: imports(name, path, modules) for name, path in modules.items()}


def layer_of(name):
    for index, (_, members) in enumerate(LAYERS):
        if name in members or any(m.endswith(".*") and name.startswith(m[:-1]) for m in members):
            return index
    return None


def internal_edges():
    modules = graph()
    return {
        name: {target for target, _ in found if target in modules and target != name} for name, found in modules.items()
    }


def test_every_module_has_a_layer_and_imports_none_above_it():
    edges = internal_edges()
    unplaced = [name for name in edges if layer_of(name) is None]
    assert not unplaced, f"place these modules in LAYERS: {unplaced}"
    upward = [
        f"{name} ({LAYERS[layer_of(name)][0]}) imports {target} ({LAYERS[layer_of(target)][0]})"
        for name, targets in edges.items()
        for target in targets
        if layer_of(target) > layer_of(name)
    ]
    assert not upward, upward


def test_the_readers_import_nothing_of_the_layers_above():
    edges = internal_edges()
    readers = LAYERS[1][1] | LAYERS[0][1]
    for name, targets in edges.items():
        if name.startswith("fmutrace.recordings"):
            above = [t for t in targets if not t.startswith("fmutrace.recordings") and t not in readers]
            assert not above, f"{name} imports {above}"


def find_cycle(edges):
    """A cycle of the graph as a list of its modules, or None."""
    state = {}  # name -> 1 while on the path, 2 when done
    path = []

    def visit(name):
        state[name] = 1
        path.append(name)
        for target in sorted(edges[name]):
            if state.get(target) == 1:
                return path[path.index(target) :] + [target]
            if target not in state:
                cycle = visit(target)
                if cycle:
                    return cycle
        path.pop()
        state[name] = 2
        return None

    for name in sorted(edges):
        if name not in state:
            cycle = visit(name)
            if cycle:
                return cycle
    return None


def test_no_import_cycle_not_even_through_an_import_inside_a_function():
    assert find_cycle(internal_edges()) is None, " -> ".join(find_cycle(internal_edges()))


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set(), "c": {"a", "b"}}) is None


def test_a_function_imports_only_the_packages_loaded_on_first_use():
    """No fmutrace module imported inside a function (a hidden cycle), no
    dependency either, except the heavy ones loaded where they are used."""
    hidden = [
        (name, target)
        for name, found in graph().items()
        for target, where in found
        if where == "function" and target.split(".")[0] not in LOADED_ON_USE
    ]
    assert not hidden, hidden


def test_internal_modules_are_private():
    public = [name for name in graph() if name not in PUBLIC and not name.rsplit(".", 1)[-1].startswith("_")]
    assert not public, f"name internal modules _name: {public}"


def test_a_posix_only_module_is_imported_on_its_platform_only():
    posix = [
        (name, target)
        for name, found in graph().items()
        for target, where in found
        if target.split(".")[0] in POSIX_ONLY and where != "module, by platform"
    ]
    assert not posix, posix


def run_python(code):
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_import_fmutrace_loads_no_heavy_package_and_no_posix_module():
    loaded = run_python("import sys, fmutrace, fmutrace.cli; print(' '.join(sorted(sys.modules)))").split()
    assert not [m for m in loaded if m.split(".")[0] in LOADED_ON_USE], loaded
    assert not [m for m in loaded if m.split(".")[0] in POSIX_ONLY and m.startswith("fmutrace")]


PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi3" / "PassThrough.fmu"


def step_case(case):
    """A PassThrough case in the folder case: u steps from 0 to 1 at 0.2,
    y follows one step later (y(t + h) = u(t))."""
    case.mkdir(parents=True)
    (case / "PassThrough_in.csv").write_text("time,u\n0,0\n0.2,1\n")
    (case / "PassThrough_ref.csv").write_text("time,y\n0,0\n0.1,0\n0.2,0\n0.3,1\n0.4,1\n")
    (case / "PassThrough_ref.opt").write_text("StartTime,0\nStopTime,0.4\nStepSize,0.1\n")
    return case


def test_a_campaign_of_plain_cases_loads_no_heavy_package(tmp_path):
    """pandas (which pyarrow's to_numpy, pa.array and pa.table import where it
    is installed) costs a short campaign a third of a second in every
    process; matplotlib is loaded for a PNG only. Read, run, compared, its
    result file and plot data written."""
    step_case(tmp_path / "cases" / "step")
    loaded = run_python(
        "import sys, fmutrace\n"
        f"c = fmutrace.compare({str(PASS_THROUGH)!r}, {str(tmp_path / 'cases')!r}, plots='all', "
        f"report={str(tmp_path / 'report')!r}, run=fmutrace.RunOptions(jobs=1))\n"
        "assert c.passed, c.summary()\n"
        "print(' '.join(sorted(sys.modules)))"
    ).split()
    assert not [m for m in loaded if m.split(".")[0] in LOADED_ON_USE], loaded


AS_ON_WINDOWS = """
import sys, types
import cffi, fmpy, fmpy.simulation, numpy, pyarrow.csv  # (before the switch: they load this platform's libraries)
import multiprocessing.connection  # (and so does this one: _winapi on Windows)
sys.modules["fcntl"] = None  # its import fails, as on Windows
msvcrt = types.ModuleType("msvcrt")  # Windows' own, reduced to the lock (this is not Windows)
msvcrt.LK_NBLCK, msvcrt.LK_UNLCK, msvcrt.locked = 2, 0, []
msvcrt.locking = lambda fd, mode, n: msvcrt.locked.append((mode, n))
sys.modules["msvcrt"] = msvcrt
sys.platform = "win32"
"""


@pytest.mark.parametrize("module", ["fmutrace", "fmutrace.cli"])
def test_fmutrace_imports_where_fcntl_does_not_exist(module):
    run_python(f"{AS_ON_WINDOWS}\nimport {module}")


def test_the_report_lock_takes_windows_lock_where_fcntl_does_not_exist(tmp_path):
    said = run_python(f"""{AS_ON_WINDOWS}
from fmutrace._journal import ReportLock
lock = ReportLock({str(tmp_path)!r})
print(open(lock.path).read().strip())
lock.release()
print(msvcrt.locked)""").splitlines()
    assert said[0].startswith("pid ") and said[1] == "[(2, 1), (0, 1)]"


PARAMETERS_AT_MOST = 6  # an internal function's; more settings travel as one object (RunOptions, CaseSettings, ...)


def functions():
    """(module, function name, its ast.arguments) of every function of the package."""
    for name, path in module_names().items():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield name, node.name, node.args


def test_no_internal_function_takes_more_than_six_parameters():
    import fmutrace

    many = [
        f"{module}.{function}"
        for module, function, args in functions()
        if len([a for a in args.posonlyargs + args.args + args.kwonlyargs if a.arg not in ("self", "cls")])
        > PARAMETERS_AT_MOST
        and function not in fmutrace.__all__
    ]
    assert not many, many


@pytest.mark.parametrize("entry", ["compare", "simulate"])
def test_the_entry_points_take_their_settings_by_keyword(entry):
    """compare(fmus, cases, *, ...) and simulate(fmu, input, *, ...)."""
    import inspect

    import fmutrace

    parameters = list(inspect.signature(getattr(fmutrace, entry)).parameters.values())
    assert [p.kind for p in parameters[:2]] == [inspect.Parameter.POSITIONAL_OR_KEYWORD] * 2
    assert all(p.kind == inspect.Parameter.KEYWORD_ONLY for p in parameters[2:]) and len(parameters) > 2


WITHOUT = (
    "import sys\nsys.modules[{module!r}] = None  # not installed, as in the base install\nfrom fmutrace import cli\n"
)


@pytest.mark.parametrize(
    "module,extra,args",
    [
        ("matplotlib", "png", ["--plots", "png", "--report", "{tmp}/report"]),
        ("distributed", "dask", ["--scheduler", "tcp://127.0.0.1:9"]),
        ("asammdf", "mdf", []),
    ],
)
def test_a_command_that_needs_a_missing_extra_names_its_pip_install_line(module, extra, args, tmp_path):
    """The base install leaves out matplotlib, Dask and asammdf: a command
    that needs one ends with exit status 2 and the line that installs it,
    no traceback (an MDF recording: reported as an invalid case)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "recordings"))
    try:
        import samples  # (the generator beside the recordings: asammdf's own writer)
    finally:
        sys.path.pop(0)
    given = [str(PASS_THROUGH), str(step_case(tmp_path / "cases" / "step"))]
    if module == "asammdf":
        given = [str(BUILD_DIR / "fmi3" / "LGF_LimRateOfChangeCI.fmu"), str(samples.write_mdf(tmp_path / "ramp.mf4"))]
    command = ["compare", *given, *(a.format(tmp=tmp_path) for a in args)]
    done = subprocess.run(
        [sys.executable, "-c", WITHOUT.format(module=module) + f"sys.exit(cli.main({command!r}))"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 2, done.stdout + done.stderr
    assert f'needs {module}, an optional part of fmutrace: pip install "fmutrace[{extra}]"' in done.stderr
    assert "Traceback" not in done.stderr
