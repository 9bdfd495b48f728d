"""./course grade: build each lab on its own, grade it (grade.py), print the table."""
import argparse
import subprocess
import sys

from . import grade
from .base import BUILD, ROOT, CourseError, show, under_root
from .base import program as executable_path
from .build import WARNING_LINES, BuildFailure, build_targets, configure, sanitizer_rerun, student_warnings
from .labs import build_features, lab_dirs, lab_targets, manifest, resolve_lab


class Grader:
    """Builds and grades labs one at a time, remembering each result, so a lab
    whose tests link an earlier lab's student code can say how that lab scores."""

    def __init__(self, solutions=False, select=None, log=sys.stdout, sanitize=True, info=True, hidden=False):
        self.solutions = solutions
        self.hidden = hidden  # also the [hidden] cases (the honesty checks)
        self.select = select
        self.log = log
        self.sanitize = sanitize
        self.info = info
        self.results = {}

    def grade(self, lab, select=None, info=True):
        """A LabResult for `lab`, with .build_errors, .warnings, .info, .crashes."""
        key = (lab, select is not None)
        if key in self.results:
            result = self.results[key]
            if info and self.info and result.info is None and manifest()[lab].get("info"):
                result.info = self.run_info(lab)
            return result
        result = grade.LabResult(lab)
        result.build_errors, result.warnings, result.info, result.crashes = [], [], None, {}
        result.max_known = None
        self.results[key] = result
        if lab not in manifest():
            result.errors.append(f"{lab} is not added in CMakeLists.txt (add_lab)")
            return result
        if self.solutions and not manifest()[lab]["reference"]:
            result.errors.append(f"{lab} has no reference in solutions/{lab}/")
            return result
        try:
            output = self.build(lab)
        except BuildFailure as failure:
            result.build_errors = failure.lines
            result.max_known = grade.source_points(ROOT / "tests" / lab, grade.lab_tag(lab))
            return result
        if not self.solutions:
            result.warnings = student_warnings(lab, output)
        suffix = "_tests_solution" if self.solutions else "_tests"
        graded = grade.grade_lab(lab, executable_path(lab + suffix), ROOT, select, hidden=self.hidden,
                                 skip_tags=skip_tags())
        result.cases, result.errors = graded.cases, result.errors + graded.errors
        if self.sanitize and not self.solutions:
            for case in [c for c in result.cases if c.signal][:2]:
                result.crashes[case.name] = sanitizer_rerun(lab, case, log=self.log)
                case.details = [*result.crashes[case.name], *case.details]
        if info and self.info and manifest()[lab].get("info"):
            result.info = self.run_info(lab)
        return result

    def build(self, lab):
        """Build what grading `lab` needs and, in the same step, the lab's executable,
        so that the next ./course run starts at once. A failure outside the
        student's own files (the executable's driver) costs only the executable:
        the tests are built and graded without it."""
        targets = lab_targets(lab, self.solutions)
        program = lab + ("_solution" if self.solutions else "")
        try:
            return build_targets([*targets, program], log=self.log, label=lab)
        except BuildFailure as failure:
            students = manifest()[lab]["student"]
            if any(student in line for line in failure.lines for student in students):
                raise
            return build_targets(targets, log=None)

    def run_info(self, lab):
        """The info program's line for the student's code (and the reference's)."""
        programs = [("the reference", f"{lab}_info_solution")] if self.solutions else [
            ("your code", f"{lab}_info")]
        if not self.solutions and manifest()[lab]["reference"]:
            programs.append(("the reference", f"{lab}_info_solution"))
        lines = []
        for who, name in programs:
            try:
                done = subprocess.run([str(executable_path(name))], cwd=ROOT, capture_output=True,
                                      encoding="utf-8", errors="replace",
                                      timeout=30, check=False)
                text = (done.stdout.strip().splitlines() or [f"exit code {done.returncode}"])[0]
            except (OSError, subprocess.TimeoutExpired) as error:
                text = f"not measured ({error})"
            lines.append(f"{who}: {text}")
        return lines

    def dependency_notes(self, lab):
        """One line per earlier lab whose STUDENT code `lab`'s tests link."""
        if self.solutions:
            return []
        notes = []
        links = manifest().get(lab, {}).get("links", {})
        for dep in sorted(d for d, kind in links.items() if kind == "student"):
            this, that = number_of(lab), number_of(dep)
            result = self.grade(dep, info=False)
            if result.build_errors:
                notes.append(f"lab {this} links your lab {that} code, which does not compile: fix it first")
                continue
            fmt = grade.fmt_points
            line = f"lab {this} links your lab {that} code: lab {that} scores {fmt(result.score)}/{fmt(result.max_score)}"
            if result.score < result.max_score or result.errors or not result.cases:
                line += " — fix it first"
            notes.append(line)
        return notes


def number_of(lab):
    return grade.lab_id(lab)[3:]


def skip_tags():
    """The graded cases this build cannot run, by tag, and why (grade.grade_lab)."""
    if build_features().get("openmp", True):
        return {}
    return {"[openmp]": "this build has no OpenMP, so there is no parallel region to count "
                        "(macOS: brew install libomp, then remove build/ and grade again)"}


def print_grades(results, notes, verbose=False):
    """Per-lab table; failed cases with the reason and their context; build
    errors, warnings, notes on earlier labs; `Score: X/Y`."""
    fmt = grade.fmt_points
    rows = [["lab", "cases", "points"]]
    for r in results:
        if r.build_errors:
            rows.append([r.lab, "-", f"0/{fmt(r.max_known)}  does not compile"])
        else:
            rows.append([r.lab, f"{len(r.passed)}/{len(r.cases) - len(r.skipped)}", f"{fmt(r.score)}/{fmt(r.max_score)}"])
    widths = [max(len(row[i]) for row in rows) for i in range(2)]
    print()
    for row in rows:
        print(f"{row[0]:<{widths[0]}}  {row[1]:>{widths[1]}}  {row[2]}")
    for r in results:
        tag = grade.lab_id(r.lab)
        if r.build_errors:
            print(f"  BUILD {tag}: the compiler's first errors:")
            for line in r.build_errors:
                print(f"    | {line}")
        for case in r.cases:
            if case.passed:
                if verbose:
                    print(f'  pass {tag} "{case.name}" ({fmt(case.points)} pts)')
                continue
            if case.skipped:
                print(f'  SKIP {tag} "{case.name}" ({fmt(case.points)} pts, not counted): {case.skipped}')
                continue
            print(f'  FAIL {tag} "{case.name}" ({fmt(case.points)} pts)')
            print(f"       {grade.terminal_reason(case)}")
            crash = r.crashes.get(case.name, [])
            for line in crash:
                print(f"       {grade.clip(line, grade.TERMINAL_CAP)}")
            context = grade.context_line(grade.CaseResult(case.name, 0, False, "", case.details[len(crash):]))
            if context:
                print(f"       {grade.clip(context, grade.TERMINAL_CAP)}")
        for error in r.errors:
            print(f"  ERROR {error}")
        if r.warnings:
            print(f"  {len(r.warnings)} compiler warning{'s' if len(r.warnings) != 1 else ''} in your "
                  f"{tag} code{' (first ' + str(WARNING_LINES) + ')' if len(r.warnings) > WARNING_LINES else ''}:")
            for line in r.warnings[:WARNING_LINES]:
                print(f"    {grade.clip(line, grade.TERMINAL_CAP)}")
        for note in notes.get(r.lab, []):
            print(f"  {note}")
        if r.info:
            print(f"  {tag} information, not graded:")
            for line in r.info:
                print(f"    {line}")
    score = sum(r.score for r in results)
    max_score = sum(r.max_known if r.build_errors else r.max_score for r in results)
    print(f"Score: {fmt(score)}/{fmt(max_score)}")


def write_results(path, results):
    """results.json, with a lab that did not compile as one failed entry."""
    for r in results:
        if r.build_errors:
            r.errors = [*r.errors, "does not compile:\n" + "\n".join(r.build_errors)]
    grade.write_gradescope(path, results)


def cmd_grade(argv):
    parser = argparse.ArgumentParser(prog="course grade")
    parser.add_argument("labs", nargs="*", metavar="labNN", help="labs to grade (default: all)")
    parser.add_argument("--solutions", action="store_true", help="grade the reference code")
    parser.add_argument("-t", "--test", metavar="PATTERN",
                        help="only the cases whose name contains PATTERN (or matches it, with * wildcards)")
    parser.add_argument("-v", "--verbose", action="store_true", help="also list the passing cases")
    parser.add_argument("--output", default=str(BUILD / "grade" / "results.json"),
                        help="Gradescope JSON (default build/grade/results.json)")
    args = parser.parse_args(argv)
    labs = list(dict.fromkeys(resolve_lab(token) for token in args.labs)) or lab_dirs()
    configure()
    if args.solutions:
        missing = [lab for lab in labs if not manifest().get(lab, {}).get("reference")]
        if missing:
            raise CourseError(f"--solutions: no reference in solutions/ for {', '.join(missing)}", code=2)
    select = grade.case_filter(args.test)
    grader = Grader(solutions=args.solutions, info=select is None)
    results = [grader.grade(lab, select) for lab in labs]
    if select is not None:
        print(f"(only the cases matching '{args.test}': "
              f"{sum(len(r.cases) for r in results)} of them)")
    notes = {r.lab: grader.dependency_notes(r.lab) for r in results}
    print_grades(results, notes, verbose=args.verbose)
    output = under_root(args.output)
    write_results(output, results)
    print(f"results: {show(output)}")
    return 1 if any(r.errors or r.build_errors for r in results) else 0
