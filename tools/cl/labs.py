"""The labs: their folders, the build's manifest of them (build/labs.json),
their demo.txt (runs, and `view:` comparisons) and rejects.txt.

CMake writes build/labs.json (cmake/AddLab.cmake): per lab its student files,
whether it has a reference, its earlier labs and which of them the graded tests
link as reference or as the student's code.
"""
import json
import shlex
from pathlib import Path

from . import grade
from .base import BUILD, ROOT, CourseError, program, show

MANIFEST = BUILD / "labs.json"


def manifest():
    """build/labs.json's "labs": {lab: {student, reference, info, deps, links}}."""
    try:
        return json.loads(MANIFEST.read_text(encoding="utf-8"))["labs"]
    except (OSError, ValueError, KeyError):
        return {}


def build_features():
    """build/labs.json's "build": what the configured build has that grading
    depends on ({"openmp": bool, "catch2": major version})."""
    try:
        return json.loads(MANIFEST.read_text(encoding="utf-8")).get("build", {})
    except (OSError, ValueError):
        return {}


def manifest_stale():
    """True when a lab or a reference appeared or went since the last configure."""
    labs = manifest()
    if not labs:
        return True
    declared = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    if any(lab not in labs and f"add_lab({lab} " in declared for lab in lab_dirs()):
        return True
    for lab, entry in labs.items():
        present = all((ROOT / "solutions" / lab / Path(f).name).is_file() for f in entry["student"])
        if present != entry["reference"]:
            return True
    return False


def lab_dirs():
    """Lab directory names, labs/labNN_*, sorted."""
    return sorted(p.name for p in (ROOT / "labs").glob("lab[0-9][0-9]_*") if p.is_dir())


def resolve_lab(token):
    """`lab01` or `lab01_single_spring` -> `lab01_single_spring`."""
    for lab in lab_dirs():
        if token in (lab, grade.lab_id(lab)):
            return lab
    known = ", ".join(grade.lab_id(lab) for lab in lab_dirs()) or "none yet"
    raise CourseError(f"unknown lab '{token}' (labs: {known})", code=2)


def executable(name):
    path = program(name)
    if not path.is_file():
        raise CourseError(f"{show(path)} not found (is it added in CMakeLists.txt?)")
    return path


def lab_targets(lab, solutions=False):
    """The targets grading `lab` needs: its graded tests (and its info program)."""
    entry = manifest().get(lab, {})
    suffix = "_solution" if solutions else ""
    targets = [f"{lab}_tests{suffix}"]
    if entry.get("info"):
        targets.append(f"{lab}_info{suffix}")
        if not solutions and entry.get("reference"):
            targets.append(f"{lab}_info_solution")
    return targets


VIEW_PREFIX = "view:"


def _demo_text_lines(lab):
    demo = ROOT / "labs" / lab / "demo.txt"
    if not demo.is_file():
        return []
    lines = (line.strip() for line in demo.read_text(encoding="utf-8").splitlines())
    return [line for line in lines if line and not line.startswith("#")]


QUICK_MARK = " # quick:"


def quick_args(args, overrides):
    """ARGS with each `--flag value` of OVERRIDES put in place of the flag's
    value there (appended where ARGS lacks the flag)."""
    args = list(args)
    for flag, value in zip(overrides[::2], overrides[1::2]):
        if flag in args[:-1]:
            args[args.index(flag) + 1] = value
        else:
            args += [flag, value]
    return args


def demo_lines(lab, quick=False):
    """The argument lists in labs/LAB/demo.txt (its runs; not its `view:` lines).
    A run may end with `# quick: --flag value ...`: with `quick` (./course test,
    ./course demo --quick) those values replace the run's, a shorter run that
    still writes every file the figures and views read."""
    runs = []
    for line in _demo_text_lines(lab):
        if line.startswith(VIEW_PREFIX):
            continue
        full, mark, overrides = line.partition(QUICK_MARK)
        args = shlex.split(full)
        if mark:
            overrides = shlex.split(overrides)
            if len(overrides) % 2 or not all(flag.startswith("--") for flag in overrides[::2]):
                raise CourseError(f"labs/{lab}/demo.txt: `# quick:` takes `--flag value` pairs: {line}")
            if quick:
                args = quick_args(args, overrides)
        runs.append(args)
    return runs


def view_lines(lab):
    """The comparisons in labs/LAB/demo.txt: `view: DIR DIR2` lines, as [DIR, DIR2]
    ({out} not yet replaced)."""
    return [shlex.split(line[len(VIEW_PREFIX):]) for line in _demo_text_lines(lab) if line.startswith(VIEW_PREFIX)]


def reject_lines(lab):
    """labs/LAB/rejects.txt: (arguments, expected text) per line `ARGS -> TEXT`."""
    path = ROOT / "labs" / lab / "rejects.txt"
    if not path.is_file():
        return []
    found = []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        args, arrow, expected = line.rpartition(" -> ")
        if not arrow or not args.strip() or not expected.strip():
            raise CourseError(f"{show(path)}:{number}: expected `ARGS -> TEXT`")
        found.append((shlex.split(args), expected.strip()))
    return found
