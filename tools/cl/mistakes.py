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
from concurrent.futures import ThreadPoolExecutor
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
    entries = json.loads(path.read_text(encoding="utf-8"))
    for index, entry in enumerate(entries):
        missing = {"id", "what", "file", "find", "replace", "fails"} - set(entry)
        if missing:
            raise CourseError(f"{path.relative_to(ROOT)}: [{index}]: missing {', '.join(sorted(missing))}", code=2)
    return entries


def write_if_changed(path, text):
    """Write `text` (a new mtime, so the build sees it) unless the file already holds it."""
    if path.is_file() and path.read_text(encoding="utf-8") == text:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")


def sync_tree():
    """BUILD/mistakes-tree/course: the course's files as they are now."""
    for relative in course_files():
        source = ROOT / relative
        try:
            write_if_changed(TREE / relative, source.read_text(encoding="utf-8"))
        except UnicodeDecodeError:
            target = TREE / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            if not target.is_file() or target.read_bytes() != source.read_bytes():
                target.write_bytes(source.read_bytes())


def tree_env():
    # Keyed on paths relative to ROOT, the tree's compiles hit the main build's
    # objects in ccache for every file but the planted one.
    return dict(os.environ, CCACHE_BASEDIR=str(ROOT))


def configure_tree():
    build_dir = TREE / "build"
    if not (build_dir / "CMakeCache.txt").is_file():
        done = subprocess.run(["cmake", "-S", str(TREE), "-B", str(build_dir), "-G", "Ninja",
                               "-DCMAKE_BUILD_TYPE=Release"], capture_output=True,
                              encoding="utf-8", errors="replace", env=tree_env())
        if done.returncode != 0:
            raise CourseError("mistakes: the scratch tree does not configure", details=done.stdout.splitlines()[-10:])


def build(targets):
    build_dir = TREE / "build"
    configure_tree()
    done = subprocess.run(["cmake", "--build", str(build_dir), "--target", *targets, "-j", "2"],
                          capture_output=True, encoding="utf-8", errors="replace", env=tree_env())
    errors = [line for line in done.stdout.splitlines() if "error" in line][:6]
    return done.returncode == 0, errors


def graded_cases(lab, program):
    return grade.list_names(program, grade.lab_tag(lab))


def case_fails(program, name):
    try:
        done = subprocess.run([str(program), name], capture_output=True,
                              encoding="utf-8", errors="replace", timeout=CASE_TIMEOUT)
    except subprocess.TimeoutExpired:
        return True
    return done.returncode != 0


def check_symptom(lab, symptom):
    """None when the planted build's run shows the symptom; else what it showed."""
    with tempfile.TemporaryDirectory(prefix="cl-symptom-") as scratch:
        scratch = Path(scratch)
        output, code, _ = run_command(symptom["command"], True, scratch, CASE_TIMEOUT, bin_dir=TREE / "build" / "bin")
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


def planted_path(lab, entry):
    """Where an entry is planted: the tree's reference file of it. The tree's
    programs are the `_solution` ones, whose every object but the planted file's
    is the main build's (the same source at the same relative path: ccache hits)."""
    return TREE / "solutions" / lab / entry["file"]


def plant(lab, entry):
    """Write the entry's mistake into the tree's reference file; None, or why it cannot be planted."""
    source = ROOT / "solutions" / lab / entry["file"]
    if not source.is_file():
        return f"solutions/{lab}/{entry['file']}: no such reference file"
    reference = source.read_text(encoding="utf-8")
    if reference.count(entry["find"]) != 1:
        return f"its 'find' occurs {reference.count(entry['find'])} times in {entry['file']}, not once"
    write_if_changed(planted_path(lab, entry), reference.replace(entry["find"], entry["replace"]))
    return None


def unplant(lab, entry):
    source = ROOT / "solutions" / lab / entry["file"]
    if source.is_file():
        write_if_changed(planted_path(lab, entry), source.read_text(encoding="utf-8"))


def targets_of(lab, entry):
    return [f"{lab}_tests_solution", *([f"{lab}_solution"] if entry.get("symptom") else [])]


def reference_sources(targets):
    """{target: the reference files (solutions/LAB/FILE) compiled into it}, from Ninja's commands."""
    build_dir = TREE / "build"
    found = {}
    for target in targets:
        done = subprocess.run(["ninja", "-C", str(build_dir), "-t", "commands", target],
                              capture_output=True, encoding="utf-8", errors="replace", check=False)
        found[target] = set(re.findall(r"solutions/(lab\d\d_\w+?/\w+\.cpp)\b", done.stdout))
    return found


def schedule(planned):
    """Rounds of (lab, entry): one entry of each of several labs, planted at once
    and built in one go, where no planted file is compiled into another plant's
    programs (a lab's tests and executable link earlier labs' references: lab 14's
    contain lab 08's). Each entry goes in the first round that can take it: the
    first entries of every lab (the longest catalogue first), then the second..."""
    configure_tree()  # so that Ninja can list what each target compiles
    longest = sorted(planned, key=lambda lab: -len(planned[lab]))
    wanted = [(lab, planned[lab][k]) for k in range(max(map(len, planned.values()), default=0))
              for lab in longest if k < len(planned[lab])]
    sources = reference_sources({t for lab, entry in wanted for t in targets_of(lab, entry)})
    rounds = []
    for lab, entry in wanted:
        mine = f"{lab}/{entry['file']}"
        uses = set().union(*(sources[t] for t in targets_of(lab, entry)))
        for taken in rounds:
            if all(other != lab and mine not in used and f"{other}/{planted['file']}" not in uses
                   for other, planted, used in taken):
                taken.append((lab, entry, uses))
                break
        else:
            rounds.append([(lab, entry, uses)])
    return [[(lab, entry) for lab, entry, _ in taken] for taken in rounds]


def judge(lab, entry, every_case, lines):
    """None when the built tree catches the planted entry (and shows its symptom); else the problem."""
    program = TREE / "build" / "bin" / f"{lab}_tests_solution"
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


def plant_round(plants, every_case, log, lines):
    """Plant one round's entries at once, build them in one go (Ninja shares
    the two cores among the labs' files), judge them two at a time, and put the
    references back; {lab: 1 when caught, else 0}."""
    start = time.monotonic()
    problems = {lab: plant(lab, entry) for lab, entry in plants}
    ready = [(lab, entry) for lab, entry in plants if problems[lab] is None]
    built, errors = build([t for lab, entry in ready for t in targets_of(lab, entry)]) if ready else (True, [])
    if not built:  # which plant breaks the build: each on its own
        alone = {lab: build(targets_of(lab, entry)) for lab, entry in ready}
    judged = [(lab, entry) for lab, entry in ready if built or alone[lab][0]]
    with ThreadPoolExecutor(max_workers=2) as pool:
        verdicts = dict(zip((lab for lab, _ in judged),
                            pool.map(lambda plant: judge(*plant, every_case, lines[plant[0]]), judged)))
    caught = {}
    for lab, entry in plants:
        problem = problems[lab] or verdicts.get(lab)
        if problem is None and lab not in verdicts:
            problem = "the planted file does not build: " + " | ".join(alone[lab][1])
        caught[lab] = record(entry, problem, time.monotonic() - start, lines[lab], log)
        unplant(lab, entry)
    return caught


def troubleshooting_gaps(lab, entries):
    """Markers in the handout without an entry, and entries marked as
    Troubleshooting whose marker is not in the handout."""
    page = (ROOT / "labs" / lab / "README.md").read_text(encoding="utf-8")
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
    """{lab: (caught, planted, lines)}; `limit` plants at most that many entries of
    a lab (an int, or {lab: int or None}). The entries are planted in rounds
    (schedule): one entry of each of several labs at once."""
    sync_tree()
    limits = limit if isinstance(limit, dict) else {lab: limit for lab in labs}
    catalogues = {lab: catalogue(lab) for lab in labs}
    planned = {lab: entries[:limits.get(lab)] if limits.get(lab) else entries
               for lab, entries in catalogues.items() if entries}
    caught = {lab: 0 for lab in planned}
    lines = {lab: [] for lab in planned}
    for plants in schedule(planned):
        for lab, got in plant_round(plants, every_case, log, lines).items():
            caught[lab] += got
    return {lab: (caught[lab], len(entries), lines[lab] + troubleshooting_gaps(lab, catalogues[lab]))
            for lab, entries in planned.items()}


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
