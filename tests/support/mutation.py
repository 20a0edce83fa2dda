"""Mutation testing of the kernel, the core and the FMI glue.

    cd tests && python -m support.mutation --build-dir ../build [--sample N --seed S] [--jobs J]

universalmutator (pinned in tests/requirements.txt) writes every mutant of
each file in FILES: one line changed. Each mutant is compiled with the
release flags of the build (its compile_commands.json), in every
translation unit that includes the file: each FMU's one unit
(<Model>_fmi<2|3>.c in the build tree, cmake/FmuSources.cmake), and for the
kernel the kernel's C tests. Then:

- a mutant that does not compile (the build has -Werror) is stillborn;
- a mutant whose object code equals the original's cannot change behaviour
  (trivial compiler equivalence): equivalent, proved by the compiler;
- mutants with the same object code as each other are one mutant: the
  first is tested, the others share its outcome;
- every other one is linked into the ten product FMUs (and the kernel's C
  tests), which then run: the kernel's C tests, then TESTS through pytest,
  stopping at the first failure. A failure or a hang kills the mutant.

A mutant that survives must be killed by a new test, or be listed in
tests/equivalent_mutants.txt with a one-line proof that it cannot change
behaviour. The exit status is 1 for a survivor not on that list, a listed
mutant that a test kills (--check-listed) or an entry that names no mutant.

Every outcome is appended to build/mutation/journal.jsonl as it is known.
--resume keeps the recorded stillborn, equivalent and killed outcomes of
mutants of the same sources (tests are only ever added: a kill stands),
and the survivors of the same tests; it tests the rest.
"""

import argparse
import hashlib
import json
import os
import random
import shlex
import shutil
import signal
import sys
import threading
import time
import zipfile
from collections import Counter, defaultdict
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from support.fmu_driver import MODELS
from support.process import Timeout, kill_all, run

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "fmu_src"
FILES = (
    "rate_limiter.c",
    "rate_limiter.h",
    "rate_limiter_rules.h",
    "fmu_core.c",
    "fmu_model_exchange.c",
    "fmu_state.c",
    "fmi_entries.h",
    "fmi3_unsupported.h",
    "fmi2_glue.c",
    "fmi3_glue.c",
)
KERNEL = ("rate_limiter.c", "rate_limiter.h", "rate_limiter_rules.h")
EQUIVALENTS = REPO / "tests" / "equivalent_mutants.txt"
PLATFORM = {2: "linux64", 3: "x86_64-linux"}
# pytest files, most kills per second first (the run stops at the first failure; ordered from the journal of
# the full run's first 1,300 mutants of fmu_core.c: test_misuse.py caught 163 in 2 s of tests,
# test_conformance.py 54 in 11 s)
TESTS = (
    "fmu/test_misuse.py",
    "fmu/test_reference.py",
    "fmu/test_state.py",
    "fmu/test_model_exchange.py",
    "fmu/test_bad_arguments.py",
    "fmu/test_conformance.py",
    "fmu/test_vendor_interpretations.py",
    "fmu/test_long_runs.py",
    "repo/test_model_description.py",
    "fmu/test_random.py",
    "fmu/test_hostile.py",
    "fmu/test_acceleration.py",
)
# outcomes a resumed run keeps: they depend on the sources and the build's flags alone, or (killed) stand
# because tests are only added
KEPT = ("stillborn", "equivalent", "killed")
COMPILE_SECONDS = 120
KERNEL_SECONDS = 120
PYTEST_SECONDS = 600  # a mutant that makes a test loop for ever is killed by this bound


def hash_files(h, paths):
    """h fed each file's path in the repository and its bytes, in path order."""
    for path in sorted(paths):
        h.update(path.relative_to(REPO).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return h


def tests_digest(sanitized):
    """The tests a survivor survived: every file under tests/ but the list of equivalents."""
    tests = (
        p
        for p in (REPO / "tests").rglob("*")
        if p.is_file()
        and p != EQUIVALENTS
        and not any(part.startswith((".", "__pycache__")) for part in p.relative_to(REPO).parts)
    )
    return hash_files(hashlib.sha256(b"sanitized" if sanitized else b""), tests).hexdigest()


def inputs_digest(build_dir):
    """What a mutant's outcome depends on besides its own text and the tests: the product's other sources
    and the build's flags. Tests are only added, so a kill stands when they change."""
    h = hash_files(hashlib.sha256(), (p for p in SOURCE.rglob("*") if p.is_file()))
    # the flags, wherever the clone and its build tree are: a journal can be carried to another tree
    flags = (build_dir / "compile_commands.json").read_text()
    h.update(flags.replace(str(build_dir), "<build>").replace(str(REPO), "<repo>").encode())
    return h.hexdigest()


@dataclass
class Mutant:
    file: str  # name in fmu_src
    line: int  # 1-based
    before: str
    after: str
    text: str  # the whole mutated file
    key: str = ""  # file | before | after: what tests/equivalent_mutants.txt names
    outcome: str = ""  # stillborn, equivalent, listed, killed, survived
    detail: str = ""  # the compiler's or the killing test's word
    digest: str = ""  # the mutated objects' hash
    identity: str = ""  # its name in the journal: this mutant of these sources with these flags
    above: tuple = ()  # the lines above it, nearest first: tell apart mutants of lines that read the same

    def __post_init__(self):
        self.key = f"fmu_src/{self.file} | {self.before.strip()} | {self.after.strip()}"

    def keys(self):
        """The keys an entry of the list can name it by: with the lines above it (most first), then without."""
        return [" | ".join((self.key,) + self.above[:n]) for n in range(len(self.above), 0, -1)] + [self.key]

    def proof(self, equivalents):
        """The list's proof for this mutant, or None."""
        return next((equivalents[k] for k in self.keys() if k in equivalents), None)

    def label(self):
        return f"{self.file}:{self.line}: {self.before.strip()}  =>  {self.after.strip()}"


def universalmutator(venv_bin):
    exe = venv_bin / "mutate"
    if not exe.exists():
        sys.exit(f"{exe} not found: universalmutator is installed by the test command (tests/requirements.txt)")
    return exe


def generate(file, work, venv_bin):
    """Every mutant of fmu_src/<file>, as universalmutator writes them."""
    original = (SOURCE / file).read_text()
    digest = hashlib.sha256(original.encode()).hexdigest()[:16]
    folder = work / "mutants" / f"{file}-{digest}"
    if not (folder / "done").exists():
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        run(
            [str(universalmutator(venv_bin)), str(SOURCE / file), "c", "--noCheck", "--mutantDir", str(folder)],
            cwd=folder,
            timeout=600,
            what=f"universalmutator on {file}",
            check=True,
        )
        (folder / "done").touch()
    lines = original.splitlines(keepends=True)
    mutants = []
    stem, suffix = file.rsplit(".", 1)
    for path in sorted(folder.glob(f"{stem}.mutant.*.{suffix}"), key=lambda p: int(p.name.split(".")[-2])):
        text = path.read_text()
        changed = text.splitlines(keepends=True)
        if len(changed) != len(lines):
            continue  # universalmutator changes one line; anything else is not one of ours
        diff = [i for i, (a, b) in enumerate(zip(lines, changed, strict=True)) if a != b]
        if len(diff) == 1:
            i = diff[0]
            mutants.append(
                Mutant(
                    file,
                    i + 1,
                    lines[i].rstrip("\n"),
                    changed[i].rstrip("\n"),
                    text,
                    above=tuple(line.strip() for line in reversed(lines[max(0, i - 3) : i])),
                )
            )
    return mutants


def read_equivalents(path=None):
    """{key: proof}: blocks of 'file', '- before', '+ after' (one or more: the
    spellings of one mutant share its proof), 'why: proof'."""
    path = path or EQUIVALENTS
    entries, block = {}, {}
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        if line.startswith("  - "):
            block["before"] = line[4:]
        elif line.startswith("  + "):
            block.setdefault("after", []).append(line[4:])
        elif line.startswith("  above: "):  # each one line further up
            block.setdefault("above", []).append(line[9:].strip())
        elif line.startswith("  why: "):
            if not {"file", "before", "after"} <= set(block) <= {"file", "before", "after", "above"}:
                raise SystemExit(f"{path}:{number}: 'why:' without its file, '-' and '+' lines")
            for after in block["after"]:
                key = " | ".join(
                    [f"{block['file']} | {block['before'].strip()} | {after.strip()}"] + block.get("above", [])
                )
                if key in entries:
                    raise SystemExit(f"{path}:{number}: this mutant is listed already")
                entries[key] = line[7:]
            block = {}
        elif not line.startswith(" "):
            block = {"file": line.strip()}
        else:
            raise SystemExit(f"{path}:{number}: not a line of an entry: {line!r}")
    return entries


class Builder:
    """Compiles and links as the build tree does, from its compile_commands.json."""

    def __init__(self, build_dir, work):
        self.build = build_dir
        self.work = work
        database = json.loads((build_dir / "compile_commands.json").read_text())
        # translation unit -> compiler arguments; a unit is named as CMake names its object: by its path
        # in the build tree (an FMU's generated unit), else in the source tree (fmu_src, tests/c)
        self.commands = {}
        self.files = {}  # unit -> its file
        for entry in database:
            source = Path(entry["file"])
            target = entry.get("output") or entry["command"].split(" -o ")[1].split()[0]
            if target.startswith(tuple(f"CMakeFiles/{name}.dir/" for name in self.targets())):
                base = build_dir if source.is_relative_to(build_dir) else REPO
                name = source.relative_to(base).as_posix()
                self.commands.setdefault(name, shlex.split(entry["command"]))
                self.files[name] = source
        # the units of the product: the FMUs' and the kernel's own (the C tests link it)
        self.units = sorted(u for u in self.commands if not u.startswith("tests/"))
        self.links = {
            t: (build_dir / "CMakeFiles" / f"{t}.dir" / "link.txt").read_text().split() for t in self.targets()
        }

    def includes(self, unit):
        """The files of fmu_src a unit compiles: an FMU's unit, those it includes; a file of fmu_src, itself."""
        if unit.startswith("fmu_src/"):
            return {Path(unit).name}
        return {
            line.split('"')[1] for line in self.files[unit].read_text().splitlines() if line.startswith('#include "')
        }

    @staticmethod
    def targets():
        return [f"{m}_fmi{v}" for m in MODELS for v in (2, 3)] + ["test_kernel"]

    def compile(self, tree, unit, output):
        """Compile <unit> with the build's flags; tree stands in for the source tree (a unit of fmu_src or
        tests/c is compiled from there; an FMU's unit in the build tree includes its files from there)."""
        args = [
            str(tree / unit) if a == str(REPO / unit) else a.replace(str(SOURCE), str(tree / "fmu_src"))
            for a in self.commands[unit]
        ]
        for flag in ("-MT", "-MF"):  # no dependency files
            if flag in args:
                i = args.index(flag)
                del args[i : i + 2]
        args = [a for a in args if a != "-MD"]
        args[args.index("-o") + 1] = str(output)
        # the object code must not depend on where the tree is (the last map that matches wins)
        args.append(f"-ffile-prefix-map={tree}=.")
        output.parent.mkdir(parents=True, exist_ok=True)
        return run(args, cwd=self.build, timeout=COMPILE_SECONDS, what=f"compiling {unit}")

    def link(self, target, objects, output):
        """Link target from objects ({unit: path}), into output."""
        args = list(self.links[target])
        for i, a in enumerate(args):
            if a.endswith(".c.o"):
                unit = a.split(".dir/", 1)[1][:-2]
                args[i] = str(objects[unit])
        args[args.index("-o") + 1] = str(output)
        output.parent.mkdir(parents=True, exist_ok=True)
        done = run(args, cwd=self.build, timeout=COMPILE_SECONDS, what=f"linking {target}")
        if done.returncode:  # a mutant that hides or renames a function: it does not build
            errors = [line for line in done.stderr.splitlines() if "undefined" in line or "error" in line]
            raise Stillborn(f"linking {target}: " + (errors[0] if errors else done.stderr.strip()[-200:]))


class Stillborn(Exception):
    """The mutant does not build."""


def units_of(file, builder):
    """The translation units whose objects a change of fmu_src/<file> can change."""
    if file.endswith(".c"):
        return [u for u in builder.units if file in builder.includes(u)]
    return builder.units + ["tests/c/test_kernel.c"]


def write_tree(folder, file=None, text=None):
    """A copy of fmu_src (and the kernel's tests) with <file> replaced by text."""
    shutil.rmtree(folder, ignore_errors=True)
    shutil.copytree(SOURCE, folder / "fmu_src")
    if file:
        (folder / "fmu_src" / file).write_text(text)
    (folder / "tests" / "c").mkdir(parents=True)
    shutil.copy(REPO / "tests" / "c" / "test_kernel.c", folder / "tests" / "c")


def object_name(unit):
    return unit.replace("/", "_") + ".o"


@dataclass
class Baseline:
    tree: Path
    objects: dict = field(default_factory=dict)  # unit -> path
    digests: dict = field(default_factory=dict)  # unit -> sha256 of the object


def compile_baseline(builder, work):
    base = Baseline(work / "baseline")
    write_tree(base.tree)
    for unit in builder.units + ["tests/c/test_kernel.c"]:
        out = base.tree / "obj" / object_name(unit)
        done = builder.compile(base.tree, unit, out)
        if done.returncode:
            sys.exit(f"the unmutated {unit} does not compile:\n{done.stderr}")
        base.objects[unit] = out
        base.digests[unit] = hashlib.sha256(out.read_bytes()).hexdigest()
    return base


def compile_mutant(mutant, index, builder, base, work):
    """Stillborn, equivalent, or the mutated objects' digest."""
    tree = work / "run" / str(index)
    write_tree(tree, mutant.file, mutant.text)
    changed = []
    for unit in units_of(mutant.file, builder):
        out = tree / "obj" / object_name(unit)
        done = builder.compile(tree, unit, out)
        if done.returncode:
            mutant.outcome = "stillborn"
            first = [line for line in done.stderr.splitlines() if "error" in line]
            mutant.detail = first[0] if first else done.stderr.strip()[-200:]
            shutil.rmtree(tree, ignore_errors=True)
            return
        digest = hashlib.sha256(out.read_bytes()).hexdigest()
        if digest != base.digests[unit]:
            changed.append(f"{unit}:{digest}")
    if not changed:
        mutant.outcome = "equivalent"
        mutant.detail = "the same object code as the original"
        shutil.rmtree(tree, ignore_errors=True)
        return
    mutant.digest = hashlib.sha256("\n".join(changed).encode()).hexdigest()


def fmu_bytes(build_dir, model, version, library):
    """The product FMU with its host binary replaced by library."""
    source = build_dir / f"fmi{version}" / f"{model}.fmu"
    inside = f"binaries/{PLATFORM[version]}/{model}.so"
    with zipfile.ZipFile(source) as z_in:
        entries = [
            (info.filename, library.read_bytes() if info.filename == inside else z_in.read(info))
            for info in z_in.infolist()
        ]
    return entries


def lifecycle_command(builder, objects, stage, version):
    """RateLimiter (FMI version) linked from objects and unpacked in stage as test_lifecycle loads it; the
    command that runs the harness on it: every kind of call, allocations balanced, many instances."""
    builder.link(f"RateLimiter_fmi{version}", objects, stage / "binaries" / PLATFORM[version] / "RateLimiter.so")
    shutil.copy(builder.build / "stage" / f"fmi{version}" / "RateLimiter" / "modelDescription.xml", stage)
    return [str(builder.build / "test_lifecycle"), str(version), str(stage), "2000", "200"]


def harness_kill(what, args, timeout, telling):
    """None if the C harness passes; else ("killed", why), why being its first line that telling picks,
    else its last line."""
    try:
        done = run(args, timeout=timeout, what=what)
    except Timeout:
        return "killed", f"{what} did not end within {timeout} s"
    if not done.returncode:
        return None
    lines = (done.stdout + done.stderr).strip().splitlines()
    told = [line for line in lines if telling(line)]
    return "killed", f"{what}: " + (told[0] if told else lines[-1] if lines else f"exit {done.returncode}")[:300]


class Sanitized:
    """The survivors' last stage: the mutant built with the sanitizer tree's flags (ASan and UBSan, any
    finding fatal), then the kernel's C tests (kernel mutants) and the lifecycle harness on RateLimiter. An
    out-of-bounds read or undefined behaviour that changes no value the tests see is still a bug."""

    def __init__(self, build_dir, work):
        self.builder = Builder(build_dir, work / "sanitized")
        # the unmutated objects, from the sources as they are at the start, as the release ones
        self.base = compile_baseline(self.builder, self.builder.work)

    def check(self, mutant, tree):
        builder, out = self.builder, tree / "sanitized"
        objects = dict(self.base.objects)
        for unit in units_of(mutant.file, builder):
            objects[unit] = out / "obj" / object_name(unit)
            done = builder.compile(tree, unit, objects[unit])
            if done.returncode:
                raise Stillborn(f"with the sanitizers: {done.stderr.strip()[-200:]}")
        harnesses = []
        if mutant.file in KERNEL:
            builder.link("test_kernel", objects, out / "test_kernel")
            harnesses.append(("the kernel's C tests", [str(out / "test_kernel")]))
        for version in (2, 3):
            if mutant.file != f"fmi{5 - version}_glue.c":  # else that version's binaries are the original ones
                harnesses.append(
                    (
                        f"test_lifecycle (FMI {version})",
                        lifecycle_command(builder, objects, out / "stage" / f"fmi{version}", version),
                    )
                )
        for what, args in harnesses:
            kill = harness_kill(
                f"{what} with the sanitizers",
                args,
                KERNEL_SECONDS * 5,
                lambda line: "ERROR:" in line or "runtime error" in line,
            )
            if kill:
                return kill
        return "survived", ""


def test_mutant(mutant, index, builder, base, work, venv_python, sanitized=None):
    """Link the mutated objects into the FMUs and the kernel tests; run them."""
    tree = work / "run" / str(index)
    objects = dict(base.objects)
    for unit in units_of(mutant.file, builder):
        objects[unit] = tree / "obj" / object_name(unit)
    build = tree / "build"
    try:
        if mutant.file in KERNEL:
            kernel = tree / "test_kernel"
            builder.link("test_kernel", objects, kernel)
            kill = harness_kill(
                "the kernel's C tests", [str(kernel)], KERNEL_SECONDS, lambda line: ", expected " in line
            )
            if kill:
                return kill
        for version in (2, 3):
            if mutant.file == f"fmi{5 - version}_glue.c":
                # the other version's glue: its FMUs are the original ones
                (build / f"fmi{version}").parent.mkdir(parents=True, exist_ok=True)
                (build / f"fmi{version}").symlink_to(builder.build / f"fmi{version}", target_is_directory=True)
                continue
            for model in MODELS:
                library = tree / "lib" / f"fmi{version}" / f"{model}.so"
                builder.link(f"{model}_fmi{version}", objects, library)
                out = build / f"fmi{version}" / f"{model}.fmu"
                out.parent.mkdir(parents=True, exist_ok=True)
                with zipfile.ZipFile(out, "w", zipfile.ZIP_STORED) as z_out:
                    for name, data in fmu_bytes(builder.build, model, version, library):
                        z_out.writestr(name, data)
            if mutant.file not in KERNEL or mutant.file.endswith(".h"):
                kill = harness_kill(
                    f"test_lifecycle (FMI {version})",
                    lifecycle_command(builder, objects, tree / "stage" / f"fmi{version}", version),
                    KERNEL_SECONDS,
                    lambda line: False,
                )
                if kill:
                    return kill
        env = dict(os.environ, RL_BUILD_DIR=str(build), RL_ORACLE_CACHE=str(work / "oracle"))
        args = [
            str(venv_python),
            "-m",
            "pytest",
            "-x",
            "-q",
            "-p",
            "no:cacheprovider",
            "--hypothesis-seed=0",
            "-o",
            "timeout=300",
            *TESTS,
        ]
        try:
            done = run(args, cwd=REPO / "tests", env=env, timeout=PYTEST_SECONDS, what="pytest")
        except Timeout:
            return "killed", f"pytest did not end within {PYTEST_SECONDS} s"
        if done.returncode:
            failed = [line for line in done.stdout.splitlines() if line.startswith(("FAILED", "ERROR"))]
            last = done.stdout.strip().splitlines()[-1:] or [f"pytest exited with {done.returncode}"]
            return "killed", (failed or last)[0][:300]
        return sanitized.check(mutant, tree) if sanitized else ("survived", "")
    except Stillborn as error:
        return "stillborn", str(error)
    finally:
        shutil.rmtree(tree, ignore_errors=True)


class Journal:
    """Append-only record of outcomes, one JSON line per mutant, flushed as each is known."""

    def __init__(self, path, resume, tests):
        self.kept = {}
        self.tests = tests
        if resume and path.exists():
            for line in path.read_text().splitlines():
                try:
                    record = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut by a kill
                if record.get("outcome") in KEPT or (
                    record.get("outcome") == "survived" and record.get("tests") == tests
                ):
                    self.kept[record["identity"]] = (record["outcome"], record["detail"])
        path.parent.mkdir(parents=True, exist_ok=True)
        self.file = open(path, "a" if resume else "w")
        self.file.write("\n")  # closes a line cut by a kill

    def record(self, m, outcome, detail):
        record = dict(identity=m.identity, label=m.label(), outcome=outcome, detail=detail)
        if outcome == "survived":  # kept while the tests are these
            record["tests"] = self.tests
        self.file.write(json.dumps(record) + "\n")
        self.file.flush()

    def close(self):
        self.file.close()


def parallel(jobs, function, items):
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(function, items))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build-dir", type=Path, required=True, help="a build tree of the test command")
    parser.add_argument("--files", nargs="+", default=list(FILES), choices=FILES)
    parser.add_argument("--sample", type=int, help="test this many mutants, drawn with --seed")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--report", type=Path, help="write every mutant's outcome here (JSON)")
    parser.add_argument(
        "--check-listed", action="store_true", help="test the listed equivalents too: each must survive"
    )
    parser.add_argument("--listed", action="store_true", help="test only the listed equivalents")
    parser.add_argument(
        "--only",
        nargs="+",
        metavar="TEXT",
        help="test only the mutants whose label (file:line: before  =>  after) contains one of these",
    )
    parser.add_argument(
        "--sanitizer-build",
        type=Path,
        help="a build tree with -DRL_SANITIZE=ON (default: <build-dir>/sanitize, if built)",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="keep the journal's stillborn, equivalent and killed outcomes, and its survivors of "
        "the same tests; test the rest",
    )
    parser.add_argument(
        "--status", action="store_true", help="with --resume: print the table from the journal alone, testing nothing"
    )
    args = parser.parse_args(argv)

    def stop(signum, frame):  # the tests running go too; the journal has every outcome known so far
        kill_all()
        os._exit(128 + signum)

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    build_dir = args.build_dir.resolve()
    work = build_dir / "mutation"
    venv_bin = Path(sys.executable).parent
    started = time.monotonic()

    equivalents = read_equivalents()
    mutants = [m for f in args.files for m in generate(f, work, venv_bin)]
    generated = len(mutants)
    # an entry must name a mutant there is (the list follows the code)
    named = {k for m in mutants for k in m.keys()}
    stale = sorted(set(equivalents) - named) if set(args.files) == set(FILES) else []
    for key in stale:
        print(f"STALE {EQUIVALENTS.name}: no such mutant: {key}")
    if args.listed:  # the list's entries alone, each tested: each must survive
        mutants = [m for m in mutants if m.proof(equivalents)]
        args.check_listed = True
    if args.only:
        mutants = [m for m in mutants if any(text in m.label() for text in args.only)]
    if args.sample is not None and args.sample < len(mutants):
        mutants = sorted(random.Random(args.seed).sample(mutants, args.sample), key=lambda m: (m.file, m.line))
    print(
        f"{generated} mutants of {', '.join(args.files)}; testing {len(mutants)}"
        + (f" (seeded sample, seed {args.seed})" if args.sample is not None else ""),
        flush=True,
    )

    sanitizer_build = (args.sanitizer_build or build_dir / "sanitize").resolve()
    sanitizing = (sanitizer_build / "test_lifecycle").exists()
    if not sanitizing:
        print(f"no sanitizer tree at {sanitizer_build}: survivors are not built with the sanitizers", flush=True)
    journal = Journal(work / "journal.jsonl", args.resume, tests_digest(sanitizing))
    inputs = inputs_digest(build_dir)
    for m in mutants:
        m.identity = hashlib.sha256(f"{inputs}\0{m.file}\0{m.text}".encode()).hexdigest()
        if m.identity in journal.kept:
            m.outcome, m.detail = journal.kept[m.identity]
            if m.outcome == "killed" and m.proof(equivalents):
                m.outcome, m.detail = "wrongly listed", f"listed as equivalent, but {m.detail}"
            elif m.outcome == "survived" and m.proof(equivalents):
                m.outcome, m.detail = "listed", m.proof(equivalents)
    kept = sum(1 for m in mutants if m.outcome)
    if args.resume:
        print(f"{kept} outcomes kept from {work / 'journal.jsonl'}", flush=True)
    if args.status:  # a long run's progress: what the journal knows of these sources and tests
        for m in mutants:
            if not m.outcome:
                m.outcome, m.detail = ("listed", m.proof(equivalents)) if m.proof(equivalents) else ("untested", "")
        print(summary(mutants))
        report_failures(mutants)
        return 0

    builder = Builder(build_dir, work)
    base = compile_baseline(builder, work)
    sanitized = Sanitized(sanitizer_build, work) if sanitizing else None
    shutil.rmtree(work / "run", ignore_errors=True)
    groups = {}  # object code digest -> the mutants that compile to it; the first one is tested for all
    lock = threading.Lock()

    def compile_and_test(item):
        """Compiled just before it is tested, so a stopped run loses only the mutants in hand."""
        index, m = item
        compile_mutant(m, index, builder, base, work)
        with lock:
            if m.outcome:  # stillborn, or the original's object code
                journal.record(m, m.outcome, m.detail)
                return
            members = groups.setdefault(m.digest, [])
            members.append(m)
            first = members[0]
            listed = m.proof(equivalents) and not args.check_listed
            if first is not m:
                if first.outcome not in ("", "listed"):  # else the first one records its group when tested
                    journal.record(m, first.outcome, f"same object code as {first.label()}")
            elif listed:
                m.outcome, m.detail = "listed", m.proof(equivalents)
        if first is not m or listed:  # not tested: its tree goes, outside the lock
            shutil.rmtree(work / "run" / str(index), ignore_errors=True)
            return
        outcome, detail = test_mutant(m, index, builder, base, work, sys.executable, sanitized)
        with lock:
            m.outcome, m.detail = outcome, detail
            for member in members:
                journal.record(member, outcome, detail if member is m else f"same object code as {m.label()}")
        print({"killed": ".", "survived": "S"}.get(outcome, "x"), end="", flush=True)  # x: does not link

    todo = [(i, m) for i, m in enumerate(mutants) if not m.outcome]
    print(f"compiling and testing {len(todo)}", flush=True)
    parallel(args.jobs, compile_and_test, todo)
    journal.close()
    print()
    settle(groups.values(), equivalents)
    shutil.rmtree(work / "run", ignore_errors=True)

    print(summary(mutants))
    failures = report_failures(mutants)
    if args.report:
        args.report.write_text(
            json.dumps(
                [
                    dict(file=m.file, line=m.line, before=m.before, after=m.after, outcome=m.outcome, detail=m.detail)
                    for m in mutants
                ],
                indent=1,
            )
        )
    print(f"{time.monotonic() - started:.0f} s")
    return 1 if failures or stale else 0


def settle(groups, equivalents):
    """Each group of mutants with the same object code takes its tested first member's outcome. A group
    with a listed member is listed if it survived; if it was killed, its listed members are wrongly listed."""
    for members in groups:
        first = members[0]
        listed = [m for m in members if m.proof(equivalents)]
        for m in members[1:]:
            m.outcome, m.detail = first.outcome, f"same object code as {first.label()}: {first.detail}"
        if not listed:
            continue
        if first.outcome in ("survived", "listed"):
            for m in members:
                m.outcome, m.detail = "listed", m.proof(equivalents) or f"same object code as {listed[0].label()}"
        elif first.outcome == "killed":
            for m in listed:
                m.outcome, m.detail = "wrongly listed", f"listed as equivalent, but {first.detail}"


def report_failures(mutants):
    """Print the survivors and the listed mutants a test kills; return how many there are."""
    failures = [m for m in mutants if m.outcome in ("survived", "wrongly listed")]
    for m in failures:
        print(f"SURVIVED {m.label()}" if m.outcome == "survived" else f"WRONGLY LISTED {m.label()}: {m.detail}")
    return len(failures)


def summary(mutants):
    """Per file: how many of each outcome, and the score (killed of those not equivalent)."""
    counts = defaultdict(Counter)
    for m in mutants:
        counts[m.file][m.outcome] += 1
        counts["all"][m.outcome] += 1
    untested = counts["all"]["untested"] > 0  # --status
    rows = [
        "| file | mutants | stillborn | same object code | listed equivalent | killed | survived | score |"
        + (" untested |" if untested else ""),
        "|---|---|---|---|---|---|---|---|" + ("---|" if untested else ""),
    ]
    for file in [f for f in FILES if f in counts] + ["all"]:
        c = counts[file]
        live = c["killed"] + c["survived"]
        score = f"{100 * c['killed'] / live:.1f} %" if live else "-"
        rows.append(
            f"| {file} | {sum(c.values())} | {c['stillborn']} | {c['equivalent']} | {c['listed']} "
            f"| {c['killed']} | {c['survived']} | {score} |" + (f" {c['untested']} |" if untested else "")
        )
    return "\n".join(rows)


if __name__ == "__main__":
    sys.exit(main())
