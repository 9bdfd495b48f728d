"""./course release: the student tree for the week of lab NN.

Every file of the course (git's tracked and untracked-but-not-ignored files, or
a plain copy), with the stubs in labs/ and, in solutions/, only the reference
code of the labs before NN (released after their deadlines). The build links
those references into later labs' tests and executables (cmake/AddLab.cmake),
so a mistake in lab 01 is charged in lab 01 only. release_files() is the one
place that decides what ships.
"""
import argparse
import json
import re
import shutil
import subprocess
from pathlib import Path

from . import grade
from .base import BUILD, ROOT, CourseError
from .labs import lab_dirs, resolve_lab

RELEASE_MARKER = "release.json"
HIDDEN_TESTS = re.compile(r"^tests/[^/]+/hidden_[^/]*\.cpp$")  # never in a release (cl/autograder.py)
SKIPPED_DIRS = {".git", "build", "build-asan", "out", "__pycache__"}


def is_release():
    """True in a student release (the marker written by ./course release)."""
    return (ROOT / RELEASE_MARKER).is_file()


def course_files():
    """Paths (relative to ROOT) of every file of the course."""
    if (ROOT / ".git").exists() and shutil.which("git"):
        done = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others",
                               "--exclude-standard"], capture_output=True,
                              encoding="utf-8", errors="replace", check=False)
        if done.returncode == 0:
            return sorted(f for f in set(done.stdout.split("\0")) if f and (ROOT / f).is_file())
    skipped = SKIPPED_DIRS | {BUILD.name}
    files = []
    for path in ROOT.rglob("*"):
        relative = path.relative_to(ROOT)
        if path.is_file() and not skipped.intersection(relative.parts) and path.suffix != ".pyc":
            files.append(str(relative))
    return sorted(files)


def release_files(lab, keep=None):
    """(files, past labs) of the release for `lab`: everything but the solutions
    of `lab` and later labs; `keep(path)` decides the rest (default: all but the
    hidden tests, tests/*/hidden_*.cpp)."""
    keep = keep or (lambda path: not HIDDEN_TESTS.match(path))
    labs = lab_dirs()
    past = labs[:labs.index(lab)]
    missing = [p for p in past if not (ROOT / "solutions" / p).is_dir()]
    if missing:
        raise CourseError(f"no reference in solutions/ for {', '.join(missing)}: cannot release them", code=2)
    files = []
    for path in course_files():
        parts = Path(path).parts
        if parts[0] == "solutions" and len(parts) > 1 and parts[1] not in past:
            continue
        if path == RELEASE_MARKER or not keep(path):
            continue
        files.append(path)
    return files, past


def write_release(lab, dest, keep=None):
    """Write the release for `lab` into DEST (new or empty); return its file count."""
    if is_release():
        raise CourseError("this is a student release already; release from the instructor's tree", code=2)
    if dest.exists() and any(dest.iterdir()):
        raise CourseError(f"{dest} is not empty", code=2)
    files, past = release_files(lab, keep)
    for path in files:
        target = dest / path
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / path, target)
    write_marker(dest, lab, past)
    return len(files) + 1


def advance_release(tree, lab):
    """Make TREE, a release of an earlier week whose stubs are as shipped, the
    release for `lab`: add the references now due, rewrite the marker. Return the
    paths that differ from a fresh write_release(lab) (none, when all is well)."""
    files, past = release_files(lab)
    for done in past:
        if not (tree / "solutions" / done).is_dir():
            shutil.copytree(ROOT / "solutions" / done, tree / "solutions" / done)
    write_marker(tree, lab, past)
    have = {str(p.relative_to(tree)) for p in tree.rglob("*")
            if p.is_file() and not SKIPPED_DIRS.intersection(p.relative_to(tree).parts)}
    want = set(files) | {RELEASE_MARKER}
    differ = sorted(have ^ want)
    differ += [path for path in sorted(have & want - {RELEASE_MARKER})
               if (tree / path).read_bytes() != (ROOT / path).read_bytes()]
    return differ


def write_marker(dest, lab, past):
    marker = {"release": lab, "references": past,
              "note": "stubs for every lab; solutions/ holds the reference code of the labs before "
                      f"{grade.lab_id(lab)} (docs/DESIGN.md §4)"}
    (dest / RELEASE_MARKER).write_text(json.dumps(marker, indent=2) + "\n", encoding="utf-8")


def cmd_release(argv):
    parser = argparse.ArgumentParser(prog="course release")
    parser.add_argument("lab", metavar="labNN", help="the lab of the week: its and later labs' solutions stay out")
    parser.add_argument("dest", metavar="DIR", help="where to write the student tree (new or empty)")
    args = parser.parse_args(argv)
    lab = resolve_lab(args.lab)
    dest = Path(args.dest).resolve()
    count = write_release(lab, dest)
    past = release_files(lab)[1]
    print(f"{dest}: {count} files; stubs for {len(lab_dirs())} labs; reference code for "
          f"{', '.join(grade.lab_id(p) for p in past) or 'no lab'}")
    return 0
