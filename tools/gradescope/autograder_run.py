"""The Gradescope side of a lab's autograder bundle (written by ./course autograder labNN).

    python3 autograder_run.py setup   once, from setup.sh: configure and build the
                                      lab's graded tests against the stubs, list the cases
    python3 autograder_run.py run     per submission, from run_autograder: copy the
                                      student's files in, rebuild, grade, results.json

The bundle: this file, setup.sh, run_autograder, autograder.json (the lab and the
time limits) and course/ (the student release of the lab's week plus the lab's
hidden tests). It uses the tree's own tools/cl/ package (build, labs, grade).

Paths: AUTOGRADER_ROOT (default /autograder) holds submission/ and results/.
AUTOGRADER_CASE_TIMEOUT and AUTOGRADER_RUN_LIMIT (seconds) override the time
limits in autograder.json; AUTOGRADER_PREBUILD_ASAN=0 skips building the
sanitizer tests at setup (a crash then builds them during the run).
"""
import json
import os
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
TREE = HERE / "course"
sys.path.insert(0, str(TREE / "tools"))
os.environ["CL_BUILD_DIR"] = str(TREE / "build")  # never the instructor's build/

from cl import build, grade  # noqa: E402  (the bundle's own tools/cl/)
from cl.base import BIN, BUILD, ROOT  # noqa: E402
from cl.labs import manifest  # noqa: E402

AUTOGRADER_ROOT = Path(os.environ.get("AUTOGRADER_ROOT", "/autograder"))
SUBMISSION = AUTOGRADER_ROOT / "submission"
RESULTS = AUTOGRADER_ROOT / "results" / "results.json"
CONFIG = json.loads((HERE / "autograder.json").read_text(encoding="utf-8"))
LAB = CONFIG["lab"]
TAG = grade.lab_id(LAB)
STATE = BUILD / "autograder"  # the case list and pristine stubs, written by setup
HIDDEN_TAG = "[hidden]"
GRACE = 20  # seconds after the run limit before the alarm stops a build or a rerun
SANITIZER_RERUNS = 2  # crashed cases rerun under the sanitizers, at most
SHOWN_EXTRAS = 15  # extra submitted files listed by name


def seconds(name, default):
    value = os.environ.get(name)
    return float(value) if value else float(default)


def whole(value):
    return int(value) if float(value).is_integer() else value


# ---------------------------------------------------------------- setup

def setup():
    start = time.monotonic()
    build.configure(log=sys.stdout, force=True)
    targets = [f"{LAB}_tests"]
    if os.environ.get("AUTOGRADER_PREBUILD_ASAN", "1") != "0":
        targets.append(f"{LAB}_tests_asan")
    try:
        build.build_targets(targets, log=sys.stdout)
    except build.BuildFailure as failure:
        print("\n".join(failure.lines), file=sys.stderr)
        print(f"setup: {LAB}'s tests do not build against the stubs", file=sys.stderr)
        return 1
    binary = BIN / f"{LAB}_tests"
    tag = grade.lab_tag(LAB)
    errors = []
    names = grade.list_names(binary, tag)
    points = grade.case_points(binary, tag, names, errors)
    hidden = set(grade.list_names(binary, tag + HIDDEN_TAG))
    errors += [f'{tag} test case "{name}" cannot be selected by name' for name in names
               if grade.UNSELECTABLE.search(name)]
    if errors or not names:
        print("\n".join(errors or [f"no test case tagged {tag}"]), file=sys.stderr)
        return 1
    # Declaration order, the hidden cases last.
    cases = sorted(({"name": name, "points": points[name], "hidden": name in hidden} for name in names),
                   key=lambda case: case["hidden"])
    students = manifest()[LAB]["student"]
    stubs = STATE / "stubs"
    stubs.mkdir(parents=True, exist_ok=True)
    for student in students:
        shutil.copy2(TREE / student, stubs / Path(student).name)
    (STATE / "cases.json").write_text(json.dumps({"student": students, "cases": cases}, indent=2) + "\n",
                                      encoding="utf-8")
    total = sum(case["points"] for case in cases)
    print(f"{LAB}: {len(cases)} graded cases ({len(hidden)} hidden), {grade.fmt_points(total)} points; "
          f"accepts {', '.join(Path(s).name for s in students)}; setup took {time.monotonic() - start:.0f} s")
    return 0


# ---------------------------------------------------------------- run

class OutOfTime(Exception):
    pass


def on_alarm(signum, frame):
    raise OutOfTime()


class Report:
    """What results.json will say: one entry per graded case, plus notes."""

    def __init__(self, cases):
        self.cases = cases  # from cases.json
        self.outcomes = {}  # name -> (score, output)
        self.notes = []  # lines for the top of the page
        self.entries = []  # extra 0-point entries: (name, output)

    def results(self, start, unfinished):
        tests = []
        for case in self.cases:
            score, output = self.outcomes.get(case["name"], (0, unfinished))
            tests.append({"name": f"{TAG}: {case['name']}", "score": score, "max_score": case["points"],
                          "output": output,
                          "visibility": "after_published" if case["hidden"] else "visible"})
        tests += [{"name": f"{TAG}: {name}", "score": 0, "max_score": 0, "output": output,
                   "visibility": "visible"} for name, output in self.entries]
        return {"score": sum(t["score"] for t in tests), "max_score": sum(t["max_score"] for t in tests),
                "output": "\n".join(self.notes), "execution_time": round(time.monotonic() - start, 1),
                "tests": tests}

    def write(self, start, unfinished):
        RESULTS.parent.mkdir(parents=True, exist_ok=True)
        partial = RESULTS.with_suffix(".partial")
        partial.write_text(json.dumps(self.results(start, unfinished), indent=2) + "\n", encoding="utf-8")
        partial.replace(RESULTS)  # never a half-written results.json


def take_submission(students, report):
    """Put the stubs back, then the submitted files over them; note what is missing or extra."""
    submitted = sorted(p for p in SUBMISSION.rglob("*") if p.is_file()) if SUBMISSION.is_dir() else []
    used = set()
    for student in students:
        name = Path(student).name
        shutil.copyfile(STATE / "stubs" / name, TREE / student)
        found = sorted((p for p in submitted if p.name == name),
                       key=lambda p: (len(p.relative_to(SUBMISSION).parts), str(p)))
        if not found:
            report.notes.append(f"{name} is missing from your submission: its tasks score 0 "
                                f"(graded the unchanged stub). Submit a file named exactly {name}.")
            report.entries.append((f"missing file {name}", f"{name} was not in your submission; "
                                   "the tests of its tasks ran on the stub and score 0."))
            continue
        shutil.copyfile(found[0], TREE / student)
        used.add(found[0])
        if len(found) > 1:
            others = ", ".join(str(p.relative_to(SUBMISSION)) for p in found[1:])
            report.notes.append(f"graded {found[0].relative_to(SUBMISSION)}; also found {others} (ignored)")
    extras = [str(p.relative_to(SUBMISSION)) for p in submitted if p not in used
              and not any(part.startswith(".") or part == "__MACOSX" for part in p.relative_to(SUBMISSION).parts)]
    if extras:
        shown = extras[:SHOWN_EXTRAS] + ([f"... and {len(extras) - SHOWN_EXTRAS} more"]
                                         if len(extras) > SHOWN_EXTRAS else [])
        report.notes.append(f"ignored (not graded in {TAG}): {', '.join(shown)}")
    return [Path(s).name for s in students]


def grade_cases(report, deadline, case_timeout, run_limit):
    """Run each case alone with a time limit; stop starting cases at the deadline."""
    binary = BIN / f"{LAB}_tests"
    reruns = 0
    with tempfile.TemporaryDirectory(prefix="cl-autograder-") as work:
        for case in report.cases:
            left = deadline - time.monotonic()
            if left < 1:
                break
            limit = whole(min(case_timeout, round(left)))
            grade.CASE_TIMEOUT = limit
            result = grade.run_case(binary, case["name"], case["points"], Path(work), ROOT)
            if result.reason.startswith("timed out") and limit < case_timeout:
                result.reason = (f"timed out: stopped after {limit} s, when the whole submission's time "
                                 f"limit ({whole(run_limit)} s) was reached")
            elif result.reason.startswith("timed out"):
                result.reason = (f"timed out: still running after {limit} s, the time limit of one test "
                                 "(an endless loop, or far too slow?)")
            if result.signal and reruns < SANITIZER_RERUNS and deadline - time.monotonic() > 30:
                reruns += 1
                result.reason = "\n".join([result.reason, *build.sanitizer_rerun(LAB, result, log=None)])
            report.outcomes[case["name"]] = (result.score, grade.case_output(result))


def run():
    start = time.monotonic()
    case_timeout = seconds("AUTOGRADER_CASE_TIMEOUT", CONFIG["case_timeout"])
    run_limit = seconds("AUTOGRADER_RUN_LIMIT", CONFIG["run_limit"])
    deadline = start + run_limit
    state = json.loads((STATE / "cases.json").read_text(encoding="utf-8"))
    report = Report(state["cases"])
    # First a valid results.json that says the run did not finish; overwritten at the end.
    report.notes.append(f"The autograder did not finish within {whole(run_limit)} s; "
                        "the cases without a result score 0.")
    report.write(start, "not run: the autograder stopped before this test")
    report.notes = []
    unfinished = f"not run: the whole submission's time limit ({whole(run_limit)} s) was reached first"
    signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(int(run_limit) + GRACE)
    try:
        names = take_submission(state["student"], report)
        try:
            output = build.build_targets([f"{LAB}_tests"], log=None)
        except build.BuildFailure as failure:
            files = ", ".join(names)
            report.notes += [f"Your code ({files}) does not compile, so no test ran (score 0). "
                             "The compiler's first errors:",
                             *failure.lines]
            report.entries.append(("your code does not compile", "\n".join(failure.lines)))
            report.write(start, f"not run: {files} does not compile (the compiler's errors are at the top)")
            return 0
        warnings = build.student_warnings(LAB, output)
        if warnings:
            report.notes += [f"{len(warnings)} compiler warning(s) in your code (first 3):", *warnings[:3]]
        grade_cases(report, deadline, case_timeout, run_limit)
    except OutOfTime:
        report.notes.append(f"The autograder stopped at its time limit of {whole(run_limit)} s.")
    finally:
        signal.alarm(0)
    if len(report.outcomes) < len(report.cases):
        report.notes.append(f"{len(report.cases) - len(report.outcomes)} test(s) did not run: "
                            f"the whole submission's time limit ({whole(run_limit)} s) was reached.")
    report.write(start, unfinished)
    score = sum(score for score, _ in report.outcomes.values())
    total = sum(case["points"] for case in report.cases)
    print(f"{TAG}: {grade.fmt_points(score)}/{grade.fmt_points(total)} -> {RESULTS}")
    return 0


def main(argv):
    if argv == ["setup"]:
        return setup()
    if argv == ["run"]:
        return run()
    print("usage: autograder_run.py setup|run", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
