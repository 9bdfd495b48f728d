"""./course mistakes: the plausible mistakes a lab's grader must catch.

Each lab keeps a catalogue in solutions/labNN_name/mistakes.json (beside the
reference it patches, so it ships only after the deadline; the format:
docs/DESIGN.md §4, "Mistakes"): a small patch of one student file, the graded
cases it must fail, and, for a mistake the handout's Troubleshooting describes,
the symptom it shows in a run. Each entry is planted in a scratch copy of the
course (BUILD/mistakes-tree, kept between runs so that a rebuild is one file)
whose student files are the reference: the lab's tests are built against it
and the named cases must fail; with --all every graded case is run, and any
other that fails is named (a mistake should cost points in its own task).
Every Troubleshooting entry of a handout that names a mistake
(<!-- mistake: ID -->) must have its entry, and its symptom must show.
"""
import argparse
import json
import os
import re
import subprocess
import tempfile
import time
from pathlib import Path

from . import grade
from .base import BUILD, ROOT, CourseError
from .claims import read_value, run_command
from .labs import lab_dirs, resolve_lab
from .release import course_files

TREE = BUILD / "mistakes-tree" / "course"
CASE_TIMEOUT = 120
MARKER = re.compile(r"<!--\s*mistake:\s*([\w-]+)\s*-->")


def catalogue(lab):
    path = ROOT / "solutions" / lab / "mistakes.json"
    if not path.is_file():
        return []
    entries = json.loads(path.read_text())
    for index, entry in enumerate(entries):
        missing = {"id", "what", "file", "find", "replace", "fails"} - set(entry)
        if missing:
            raise CourseError(f"{path.relative_to(ROOT)}: [{index}]: missing {', '.join(sorted(missing))}", code=2)
    return entries


def write_if_changed(path, text):
    """Write `text` (a new mtime, so the build sees it) unless the file already holds it."""
    if path.is_file() and path.read_text() == text:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def sync_tree():
    """BUILD/mistakes-tree/course: the course's files as they are now."""
    for relative in course_files():
        source = ROOT / relative
        try:
            write_if_changed(TREE / relative, source.read_text())
        except UnicodeDecodeError:
            target = TREE / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            if not target.is_file() or target.read_bytes() != source.read_bytes():
                target.write_bytes(source.read_bytes())


def tree_env():
    # Keyed on paths relative to ROOT, the tree's compiles hit the main build's
    # objects in ccache for every file but the planted one.
    return dict(os.environ, CCACHE_BASEDIR=str(ROOT))


def build(targets):
    build_dir = TREE / "build"
    if not (build_dir / "CMakeCache.txt").is_file():
        done = subprocess.run(["cmake", "-S", str(TREE), "-B", str(build_dir), "-G", "Ninja",
                               "-DCMAKE_BUILD_TYPE=Release"], capture_output=True, text=True, env=tree_env())
        if done.returncode != 0:
            raise CourseError("mistakes: the scratch tree does not configure", details=done.stdout.splitlines()[-10:])
    done = subprocess.run(["cmake", "--build", str(build_dir), "--target", *targets, "-j", "2"],
                          capture_output=True, text=True, env=tree_env())
    errors = [line for line in done.stdout.splitlines() if "error" in line][:6]
    return done.returncode == 0, errors


def graded_cases(lab, program):
    return grade.list_names(program, grade.lab_tag(lab))


def case_fails(program, name):
    try:
        done = subprocess.run([str(program), name], capture_output=True, text=True, timeout=CASE_TIMEOUT)
    except subprocess.TimeoutExpired:
        return True
    return done.returncode != 0


def check_symptom(lab, symptom):
    """None when the planted build's run shows the symptom; else what it showed."""
    with tempfile.TemporaryDirectory(prefix="cl-symptom-") as scratch:
        scratch = Path(scratch)
        output, code, _ = run_command(symptom["command"], False, scratch, CASE_TIMEOUT, bin_dir=TREE / "build" / "bin")
        try:
            value = read_value(symptom["read"], output, scratch)
        except (LookupError, OSError, ValueError, KeyError, IndexError) as error:
            return f"cannot read it (exit {code}): {error}"
    expect = symptom["expect"]
    shown = {"above": lambda v: float(v) > expect.get("above", 0),
             "below": lambda v: float(v) < expect.get("below", 0),
             "equals": lambda v: v == expect.get("equals"),
             "not_equals": lambda v: v != expect.get("not_equals"),
             "contains": lambda v: str(expect.get("contains")) in str(v)}
    for kind, test in shown.items():
        if kind in expect and not test(value):
            return f"expected {kind} {expect[kind]}, got {value}"
    return None


def references_of(lab):
    """The lab's reference files, written as its student files in the tree."""
    references = {p.name: p.read_text() for p in (ROOT / "solutions" / lab).glob("*.cpp")}
    for name, text in references.items():
        write_if_changed(TREE / "labs" / lab / name, text)
    return references


def plant(lab, entry, references):
    """Write the entry's mistake into the tree's student file; None, or why it cannot be planted."""
    reference = references.get(entry["file"])
    if reference is None:
        return f"solutions/{lab}/{entry['file']}: no such reference file"
    if reference.count(entry["find"]) != 1:
        return f"its 'find' occurs {reference.count(entry['find'])} times in {entry['file']}, not once"
    write_if_changed(TREE / "labs" / lab / entry["file"], reference.replace(entry["find"], entry["replace"]))
    return None


def targets_of(lab, entry):
    return [f"{lab}_tests", *([lab] if entry.get("symptom") else [])]


def judge(lab, entry, every_case, lines):
    """None when the built tree catches the planted entry (and shows its symptom); else the problem."""
    program = TREE / "build" / "bin" / f"{lab}_tests"
    passing = [name for name in entry["fails"] if not case_fails(program, name)]
    if passing:
        return "not caught: " + "; ".join(f'"{name}" passes' for name in passing)
    if entry.get("symptom"):
        shown = check_symptom(lab, entry["symptom"])
        if shown:
            return f"caught, but the handout's symptom does not show: {shown}"
    if every_case:
        others = [c for c in graded_cases(lab, program) if c not in entry["fails"] and case_fails(program, c)]
        if others:
            lines.append(f"  note {entry['id']}: also fails {'; '.join(others[:4])}")
    return None


def record(entry, problem, seconds, lines, log):
    if problem:
        lines.append(f"  FAIL {entry['id']} ({entry['what']}): {problem}")
        return 0
    log(f"  ok   {entry['id']}: {', '.join(entry['fails'])} fail ({seconds:.0f} s)")
    return 1


def restore(lab):
    for source in (ROOT / "labs" / lab).glob("*.cpp"):
        write_if_changed(TREE / "labs" / lab / source.name, source.read_text())


def plant_all(lab, entries, every_case, log):
    """(caught, lines) for one lab's entries, planted one at a time."""
    references = references_of(lab)
    caught, lines = 0, []
    for entry in entries:
        start = time.monotonic()
        problem = plant(lab, entry, references)
        if problem is None:
            built, errors = build(targets_of(lab, entry))
            problem = judge(lab, entry, every_case, lines) if built else \
                "the planted file does not build: " + " | ".join(errors)
            write_if_changed(TREE / "labs" / lab / entry["file"], references[entry["file"]])
        caught += record(entry, problem, time.monotonic() - start, lines, log)
    restore(lab)
    return caught, lines


def plant_first_entries(labs, log):
    """{lab: (caught, 1, lines)}: the first entry of each lab planted at once and
    built in one go. A lab's tests link the earlier labs' references, never
    their student files, so the mistakes of different labs cannot meet."""
    planted, results = {}, {}
    for lab in labs:
        entries = catalogue(lab)
        if entries:
            references = references_of(lab)
            planted[lab] = (entries[0], plant(lab, entries[0], references), entries)
    targets = [t for lab, (entry, problem, _) in planted.items() if problem is None for t in targets_of(lab, entry)]
    start = time.monotonic()
    built, errors = build(targets) if targets else (True, [])
    if not built:  # which lab's plant breaks the build: each on its own
        built_alone = {lab: build(targets_of(lab, entry))[0] for lab, (entry, problem, _) in planted.items()
                       if problem is None}
    for lab, (entry, problem, entries) in planted.items():
        lines = []
        if problem is None:
            if built or built_alone.get(lab):
                problem = judge(lab, entry, False, lines)
            else:
                problem = "the planted file does not build: " + " | ".join(errors)
        caught = record(entry, problem, time.monotonic() - start, lines, log)
        results[lab] = (caught, 1, lines + troubleshooting_gaps(lab, entries))
        restore(lab)
    return results


def troubleshooting_gaps(lab, entries):
    """Markers in the handout without an entry, and entries marked as
    Troubleshooting whose marker is not in the handout."""
    page = (ROOT / "labs" / lab / "README.md").read_text()
    marked = set(MARKER.findall(page))
    ids = {entry["id"] for entry in entries}
    gaps = [f"  FAIL the handout marks '{m}', which solutions/{lab}/mistakes.json does not have"
            for m in sorted(marked - ids)]
    for entry in entries:
        if entry.get("troubleshooting") and entry["id"] not in marked:
            gaps.append(f"  FAIL {entry['id']}: a Troubleshooting entry, not marked <!-- mistake: {entry['id']} -->")
        if entry.get("troubleshooting") and not entry.get("symptom"):
            gaps.append(f"  FAIL {entry['id']}: a Troubleshooting entry without its symptom")
    return gaps


def run_mistakes(labs, limit=None, every_case=False, log=print):
    """{lab: (caught, planted, lines)}; `limit` plants at most that many entries of a lab
    (limit=1: the first entry of every lab at once, one build)."""
    sync_tree()
    if limit == 1 and not every_case:
        return plant_first_entries(labs, log)
    results = {}
    for lab in labs:
        entries = catalogue(lab)
        if not entries:
            continue
        planted = entries[:limit] if limit else entries
        caught, lines = plant_all(lab, planted, every_case, log)
        results[lab] = (caught, len(planted), lines + troubleshooting_gaps(lab, entries))
    return results


def cmd_mistakes(argv):
    parser = argparse.ArgumentParser(prog="course mistakes",
                                     description="plant each catalogued mistake (solutions/*/mistakes.json) "
                                                 "and check the grader catches it")
    parser.add_argument("labs", nargs="*", metavar="labNN", help="the labs (default: all with a catalogue)")
    parser.add_argument("--all-cases", action="store_true",
                        help="also run every other graded case, and name those a mistake fails too")
    args = parser.parse_args(argv)
    labs = [resolve_lab(token) for token in args.labs] or lab_dirs()
    # A catalogue ships with its lab's reference, after the deadline: in a
    # student tree the current week's is the instructor's (as ./course bench).
    absent = [lab for lab in labs if not (ROOT / "solutions" / lab).is_dir()]
    if absent:
        message = (f"./course mistakes {grade.lab_id(absent[0])} is the instructor's: its catalogue, "
                   f"solutions/{absent[0]}/mistakes.json, comes with the lab's reference after its deadline"
                   f"{' (and so for ' + ', '.join(grade.lab_id(lab) for lab in absent[1:]) + ')' if absent[1:] else ''}")
        if args.labs:
            raise CourseError(message, code=2)
        print(message)
    failed = 0
    for lab, (caught, planted, lines) in run_mistakes(labs, every_case=args.all_cases).items():
        print(f"mistakes {lab}: {caught}/{planted} caught")
        for line in lines:
            print(line)
        failed += caught < planted or any(line.startswith("  FAIL") for line in lines)
    return 1 if failed else 0
