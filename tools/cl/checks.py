"""./course test: everything CI checks, in the order it runs them."""
import argparse
import os
import platform
import re
import shlex
import shutil
import subprocess
import tempfile
import threading
import time
from contextlib import contextmanager, nullcontext
from pathlib import Path

from . import grade
from .autograder import check_autograder
from .base import BUILD, ROOT, CourseError, show
from .base import program as program_path
from .build import BuildFailure, build_targets, configure
from .claims import run_claims
from .demo import index_links, run_demos, write_index, write_views
from .fuzz import check_fuzz
from .grading import Grader, write_results
from .handouts import check_handouts
from .labs import lab_dirs, lab_targets, manifest, reject_lines
from .live_checks import check_live
from .measure import check_measurements
from .mistakes import catalogue, run_mistakes
from .plots import run_plots
from .portability import check_portability
from .release import is_release
from .sanitize import background_cpu, check_sanitize, start_sanitize
from .student_loop import check_student_loop
from .view_checks import check_browser


def foreground_cpu():
    """CPU seconds (user + system) of this process and of the children it has
    waited for, less those of the background sanitizer's (counted apart)."""
    times = os.times()
    return times.user + times.system + times.children_user + times.children_system - background_cpu()


class Checks:
    """Counts and prints pass/fail checks, and times the steps that make them."""

    def __init__(self):
        self.passed = 0
        self.failed = 0
        self.started = time.monotonic()
        self.cpu_started = foreground_cpu()
        self.times = []  # (step, seconds, CPU seconds or None, ran alongside other steps)

    @contextmanager
    def timed(self, step, concurrent=False):
        """Time the step; `concurrent`: it ran beside another (its wall time only,
        a row without a share, its CPU inside the row of the steps around it)."""
        start, cpu = time.monotonic(), foreground_cpu()
        try:
            yield
        finally:
            self.add_time(step, time.monotonic() - start, concurrent=concurrent,
                          cpu=None if concurrent else foreground_cpu() - cpu)

    def add_time(self, step, seconds, concurrent=False, cpu=None):
        self.times.append((step, seconds, cpu, concurrent))

    def record(self, ok, name, details=()):
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        print(f"{'ok  ' if ok else 'FAIL'}  {name}", flush=True)
        for line in details:
            print(f"        {line}")

    def print_times(self):
        """The timing table: each step's seconds and share of the whole run (a step
        that ran alongside others has no share: its time is inside theirs)."""
        total = max(time.monotonic() - self.started, 1e-9)
        if not self.times:
            return
        rest = "(the rest: listing, waiting, Python)"
        width = max(len(step) for step, *_ in [*self.times, (rest,)])
        cpu_total = foreground_cpu() - self.cpu_started + background_cpu()
        print(f"\ntiming: {total:.0f} s in all, {cpu_total:.0f} s of CPU (user + system, every process; "
              f"load at the end {os.getloadavg()[0]:.2f})")
        print(f"  {'step':<{width}}  {'wall':>9}  {'CPU':>9}  share of the wall time")
        for step, seconds, cpu, concurrent in self.times:
            share = "alongside" if concurrent else f"{100 * seconds / total:5.1f} %"
            used = "-" if cpu is None else f"{cpu:.1f} s"
            print(f"  {step:<{width}}  {seconds:7.1f} s  {used:>9}  {share}")
        counted = sum(seconds for _, seconds, _, concurrent in self.times if not concurrent)
        print(f"  {rest:<{width}}  {total - counted:7.1f} s  {'':>9}  "
              f"{100 * (total - counted) / total:5.1f} %")
        self.write_times(total, cpu_total, rest, total - counted)

    def write_times(self, total, cpu_total, rest, rest_seconds):
        """The same table as Markdown in BUILD/test-times.md, with the date, the
        machine and the result: docs/testing.md quotes that file, never a hand copy."""
        model = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text(
            encoding="utf-8", errors="replace").splitlines() if line.startswith("model name")),
            platform.processor()) if Path("/proc/cpuinfo").is_file() else platform.processor()
        machine = f"{model or platform.machine()}, {os.cpu_count()} cores, {platform.platform(terse=True)}"
        lines = [f"{time.strftime('%Y-%m-%d')}, {machine}: {total:.0f} s in all, {cpu_total:.0f} s of CPU, "
                 f"{self.passed} passed, {self.failed} failed (load at the end {os.getloadavg()[0]:.2f}).", "",
                 "| step | wall s | CPU s |", "|---|---|---|"]
        for step, seconds, cpu, concurrent in self.times:
            used = "-" if cpu is None else f"{cpu:.0f}"
            lines.append(f"| {step.strip()}{' (alongside)' if concurrent else ''} | {seconds:.0f} | {used} |")
        lines.append(f"| {rest} | {rest_seconds:.0f} | |")
        (BUILD / "test-times.md").write_text("\n".join(lines) + "\n", encoding="utf-8")

    def finish(self):
        """Print the timing table and `N passed, M failed`; return the exit code."""
        self.print_times()
        print(f"{self.passed} passed, {self.failed} failed")
        return 1 if self.failed else 0


class Beside:
    """A step run in a thread beside the foreground's, in its own tree and its
    own processes: its checks are kept and recorded when it is joined, in the
    order it made them, so the output reads as if it had run alone. Its wall
    time is a row of its own, alongside; its CPU is inside the row of the steps
    it ran beside (one process's children cannot be told apart by thread)."""

    def __init__(self, checks, step, function, *args):
        self.checks, self.step = checks, step
        self.records = []
        self.error = None
        self.seconds = 0.0
        self.thread = threading.Thread(target=self._run, args=(function, args), daemon=True)
        self.thread.start()

    def record(self, ok, name, details=()):
        self.records.append((ok, name, list(details)))

    def _run(self, function, args):
        start = time.monotonic()
        try:
            function(self, *args)
        except Exception as error:  # noqa: BLE001 -- recorded as a failed check when joined
            self.error = error
        finally:
            self.seconds = time.monotonic() - start

    def join(self):
        self.thread.join()
        for ok, name, details in self.records:
            self.checks.record(ok, name, details)
        if self.error is not None:
            self.checks.record(False, f"{self.step}: {type(self.error).__name__}: {self.error}")
        self.checks.add_time(self.step, self.seconds, concurrent=True)


def build_labs(checks, labs):
    """Build each lab's targets on its own; return the labs that built. One
    keep-going build of everything (CMake's `all`: the labs, common_tests and
    the bench programs the later checks use) comes first: it keeps both cores
    busy from the first file to the last, where lab-by-lab builds leave one
    idle at the end of each. The builds per lab then only report; a lab that does
    not compile blocks no other either way. A student release skips it: its
    checks use no bench program."""
    wanted = {}
    for lab in labs:
        entry = manifest().get(lab)
        if entry is None:
            checks.record(False, f"{lab}: not added in CMakeLists.txt (add_lab)")
            continue
        targets = [lab, *lab_targets(lab)]
        if entry["reference"]:
            targets += [f"{lab}_solution", *lab_targets(lab, solutions=True)]
        wanted[lab] = list(dict.fromkeys(targets))
    if not is_release():
        with checks.timed("build everything (one keep-going build)"):
            try:
                build_targets(["all"], log=None, keep_going=True)
            except BuildFailure:
                pass  # each lab's own build below says which and why
    built = []
    for lab, targets in wanted.items():
        try:
            with checks.timed(f"build {lab}"):
                build_targets(targets, log=None)
        except BuildFailure as failure:
            checks.record(False, f"{lab} does not build", failure.lines)
            continue
        built.append(lab)
    return built


def check_ctest(checks):
    try:
        with checks.timed("build common_tests"):
            build_targets(["common_tests"], log=None)
    except BuildFailure as failure:
        checks.record(False, "common_tests does not build", failure.lines)
        return
    with checks.timed("unit tests (ctest -L unit)"):
        done = subprocess.run(["ctest", "--test-dir", str(BUILD), "-L", "unit", "--output-on-failure"],
                              cwd=ROOT, capture_output=True, encoding="utf-8", errors="replace", check=False)
    ok = done.returncode == 0
    lines = [line for line in done.stdout.splitlines() if "tests passed" in line]
    details = [] if ok else (done.stdout + done.stderr).splitlines()
    checks.record(ok, f"ctest -L unit: {lines[-1] if lines else 'no tests found'}", details)
    unregistered = unregistered_cases()
    checks.record(not unregistered, f"every case of common_tests is a ctest of its own name "
                  f"({len(unregistered)} not)", [f'"{name}"' for name in unregistered])


def unregistered_cases():
    """The cases of common_tests that ctest does not run under their own name.
    catch_discover_tests splits a name at ';' and passes it to Catch as a test
    spec: the halves of such a case match no case, and Catch 2 passes a run
    that matched none, so the case would never run in ctest."""
    listed = "\n".join(grade.list_names(program_path("common_tests")))
    known = subprocess.run(["ctest", "--test-dir", str(BUILD), "-N", "-L", "unit"], cwd=ROOT,
                           capture_output=True, encoding="utf-8", errors="replace", check=False).stdout
    names = {match.group(1) for match in re.finditer(r"Test\s+#\d+: (.*)$", known, re.MULTILINE)}
    cases = [name.strip() for name in listed.splitlines() if name.strip()]
    return [name for name in cases if name not in names]


def check_solutions(checks, labs):
    grader = Grader(solutions=True, log=None, info=False, hidden=True)
    results = [grader.grade(lab) for lab in labs]
    write_results(BUILD / "grade" / "solutions" / "results.json", results)
    for r in results:
        fmt = grade.fmt_points
        details = [f'"{c.name}": {c.reason}' for c in r.failed] + r.errors
        ok = not details and bool(r.cases) and r.score == r.max_score
        checks.record(ok, f"{r.lab} solutions: {fmt(r.score)}/{fmt(r.max_score)}", details)


def check_stubs(checks, labs):
    grader = Grader(log=None, sanitize=False, info=False, hidden=True)
    results = [grader.grade(lab) for lab in labs]
    write_results(BUILD / "grade" / "stubs" / "results.json", results)
    for r in results:
        details = [f'passes on the stubs: "{c.name}"' for c in r.passed] + r.errors
        if not r.cases:
            summary = "no graded cases"
        elif r.passed:
            summary = f"{len(r.passed)} of {len(r.cases)} graded cases pass"
        else:
            summary = f"all {len(r.cases)} graded cases fail"
        checks.record(not details and bool(r.cases), f"{r.lab} stubs: {summary}", details)


def report_student_score(labs):
    grader = Grader(log=None)
    results = [grader.grade(lab) for lab in labs]
    write_results(BUILD / "grade" / "results.json", results)
    fmt = grade.fmt_points
    for r in results:
        if r.build_errors:
            print(f"      {r.lab} (your code): does not compile (./course grade {grade.lab_id(r.lab)})")
            continue
        print(f"      {r.lab} (your code): {fmt(r.score)}/{fmt(r.max_score)}")
        for error in r.errors:
            print(f"        {error}")
        for note in grader.dependency_notes(r.lab):
            print(f"        {note}")


def check_demo(checks, out, labs):
    shutil.rmtree(out, ignore_errors=True)
    try:
        run_demos(out, echo=False, labs=labs, quick=True)
    except CourseError as error:
        checks.record(False, f"demo: {error}", error.details)
        return
    checks.record(True, f"demo -> {show(out)}/")


def refusal_problem(program, args, expected):
    """Run PROGRAM on one bad input in a scratch folder; what is wrong with how
    it refused (None: exit code 2, one stderr line containing EXPECTED, nothing
    written). A --scene argument that starts with `{` is JSON, written to
    scratch/bad.json first; `{tmp}` is the scratch folder."""
    with tempfile.TemporaryDirectory(prefix="cl-reject-") as scratch:
        scratch = Path(scratch)
        argv = [arg.replace("{tmp}", str(scratch)) for arg in args]
        for i in range(1, len(argv)):
            if argv[i - 1] == "--scene" and argv[i].startswith("{"):
                (scratch / "bad.json").write_text(argv[i], encoding="utf-8")
                argv[i] = str(scratch / "bad.json")
        before = sorted(scratch.rglob("*"))
        try:
            done = subprocess.run([str(program), *argv], cwd=scratch, capture_output=True,
                                  encoding="utf-8", errors="replace",
                                  timeout=60, check=False)
        except subprocess.TimeoutExpired:
            return "ran past 60 s instead of refusing"
        lines = done.stderr.splitlines()
        if done.returncode != 2:
            return f"exit code {done.returncode}, not 2; stderr: {' | '.join(lines[-3:]) or '(empty)'}"
        if len(lines) != 1:
            return f"{len(lines)} stderr lines, not 1: {' | '.join(lines[:3])}"
        if expected not in lines[0]:
            return f"the line does not say '{expected}': {lines[0]}"
        written = [str(p.relative_to(scratch)) for p in sorted(scratch.rglob("*")) if p not in before]
        if written:
            return f"left output behind: {', '.join(written[:3])}"
    return None


def check_rejects(checks, labs):
    """Every line of labs/*/rejects.txt: the lab's executable refuses it (docs/DESIGN.md §3)."""
    entries = manifest()
    for lab in labs:
        try:
            cases = reject_lines(lab)
        except CourseError as error:
            checks.record(False, str(error))
            continue
        if not cases:
            continue
        name = lab + ("_solution" if entries[lab]["reference"] else "")
        program = program_path(name)
        problems = []
        for args, expected in cases:
            problem = refusal_problem(program, args, expected)
            if problem:
                problems.append(f"{shlex.join(args)}: {problem}")
        checks.record(not problems, f"{lab} refuses {len(cases) - len(problems)}/{len(cases)} bad inputs "
                      f"(labs/{lab}/rejects.txt: exit 2, one line, nothing written)", problems)


def check_views(checks, out, labs):
    """The demo's views and out/index.html: every view written, every link of
    the index resolves."""
    try:
        views = write_views(out, labs, echo=False)
    except CourseError as error:
        checks.record(False, f"views of {show(out)}: {error}", error.details)
        return
    index = write_index(out)
    missing = index_links(out)
    # A student release of an early week has no reference that keeps a trajectory.
    checks.record(not missing and (bool(views) or is_release()),
                  f"{show(index)}: {len(views)} views, every link resolves" if not missing
                  else f"{show(index)}: {len(missing)} links do not resolve", missing[:5])


def check_handout_commands(checks, labs):
    """Every command of every handout runs in its week's tree (--check)."""
    for result in check_handouts(labs):
        checks.record(not result.problems, f"handout {result.summary()}", result.problems)


def check_claims(checks, labs):
    """The quick claims of every lab, with the reference."""
    try:
        results = run_claims(labs, quick=True, solutions=True)
    except CourseError as error:
        checks.record(False, f"claims: {error}", error.details)
        return
    for lab, (held, total, failures) in results.items():
        checks.record(not failures, f"claims {lab} (quick, reference): {held}/{total} hold", failures)


# The newest labs' catalogues whole, and the first entry of every other lab's
# (docs/DESIGN.md §4); ./course mistakes runs them all.
MISTAKES_WHOLE = 2


def check_mistakes(checks, labs):
    with_catalogue = [lab for lab in labs if catalogue(lab)]
    whole = with_catalogue[-MISTAKES_WHOLE:]
    try:
        results = run_mistakes(with_catalogue, limit={lab: None if lab in whole else 1 for lab in with_catalogue},
                               log=lambda _line: None)
    except CourseError as error:
        checks.record(False, f"mistakes: {error}", error.details)
        return
    for lab, (caught, planted, lines) in results.items():
        failing = [line.strip() for line in lines if line.startswith("  FAIL")]
        checks.record(caught == planted and not failing,
                      f"mistakes {lab}: {caught}/{planted} planted mistakes caught"
                      f"{'' if lab in whole else ' (its first entry)'}", failing)


# The house's own limits (docs/DESIGN.md §1): a lab's driver holds only its
# flags, its dispatch and one run's report; a tools/cl module one concern.
# Checked, because both crept past them unnoticed (issue 35: 201 and 523).
HOUSE_LIMITS = [("labs/*/main.cpp", 200), ("tools/cl/*.py", 500)]


def check_house_limits(checks):
    """Every file of HOUSE_LIMITS within its number of lines."""
    for pattern, limit in HOUSE_LIMITS:
        over = [f"{show(path)}: {count} lines" for path in sorted(ROOT.glob(pattern))
                if (count := len(path.read_text(encoding="utf-8").splitlines())) > limit]
        checks.record(not over, f"{pattern}: at most {limit} lines each", over)


def cmd_test(argv):
    argparse.ArgumentParser(prog="course test").parse_args(argv)
    # Inside ./course test only, ccache keys a compile on paths relative to the
    # tree: the student loop's release and the autograder's bundle (in
    # BUILD/check-tree) then reuse the main build's objects of the files they
    # share (common/, the earlier labs' references, catch_main, the drivers),
    # 161 s of CPU for the loop instead of 259 s (2026-12-02, same load). The
    # price: compiler messages here say ../labs/ (the check's own lines are
    # mapped back, build.first_errors); a student's ./course grade is unchanged.
    os.environ.setdefault("CCACHE_BASEDIR", str(ROOT))
    checks = Checks()
    try:
        with checks.timed("configure"):
            configure()
    except CourseError as error:
        checks.record(False, str(error), error.details)
        return checks.finish()
    check_house_limits(checks)
    check_portability(checks)  # text I/O's encodings, the requirement messages: about a second
    # The sanitizer build compiles, then runs the suite, in the background,
    # niced, from the start: niced, it takes what the foreground leaves (the
    # main build's links and its last files, the checks that run one process
    # at a time), and it is paused while the fuzzers run (they want a core
    # each). Its results are waited for last.
    sanitizing = None if is_release() else start_sanitize(checks)
    try:
        labs = build_labs(checks, lab_dirs())
    finally:
        if sanitizing is not None:
            sanitizing.main_built.set()  # its test programs' files are now in ccache
    check_ctest(checks)
    out = BUILD / "test-demo"
    if is_release():
        print("a student release: grading your code (a score, not a check)")
        with checks.timed("grading your code"):
            report_student_score(labs)
        with_reference = [lab for lab in labs if manifest()[lab]["reference"]]
        with checks.timed("demo"):
            check_demo(checks, out, with_reference)
        with checks.timed("rejects"):
            check_rejects(checks, with_reference)
    else:
        without = [lab for lab in labs if not manifest()[lab]["reference"]]
        for lab in without:
            checks.record(False, f"{lab}: no reference in solutions/{lab}/ (the honesty check needs one)")
        labs = [lab for lab in labs if lab not in without]
        # The fuzzers run alone, one per core: beside the honesty checks (a
        # process per case) the scene loader's managed 20 k inputs in a minute
        # instead of about 300 k, and beside the sanitizer build, niced, 173 k
        # (the two cores share caches).
        fuzzing = check_fuzz(checks)
        if fuzzing:
            with sanitizing.paused() if sanitizing else nullcontext():
                fuzzing()
        with checks.timed("honesty: the solutions graded"):
            check_solutions(checks, labs)
        with checks.timed("honesty: the stubs graded"):
            check_stubs(checks, labs)
        with checks.timed("demo"):
            check_demo(checks, out, labs)
        with checks.timed("rejects"):
            check_rejects(checks, labs)
        with checks.timed("handouts: every command in its week's tree (--check)"):
            check_handout_commands(checks, labs)
        with checks.timed("claims --quick (the reference)"):
            check_claims(checks, labs)
        check_measurements(checks, out)
    with checks.timed("plots (every figure, redrawn)"):
        for script, outcome in run_plots(out, echo=False).items():
            checks.record(outcome.status in ("ok", "skipped") if is_release() else outcome.status == "ok",
                          f"plots/{script} on {show(out)}: {outcome.status}", outcome.lines)
    with checks.timed("views and out/index.html"):
        check_views(checks, out, labs)
    if "lab04_pbd" in labs and manifest()["lab04_pbd"]["reference"]:
        with checks.timed("the view in a browser (headless Chromium)"):
            check_browser(checks)
        with checks.timed("the live page in a browser (headless Chromium)"):
            check_live(checks)
    if not is_release():
        # The mistakes build in their own tree (BUILD/mistakes-tree), the student
        # loop and the autograder one after the other in check-tree: the
        # mistakes run beside those two, so that the end of ./course test, after
        # the sanitizer's runs, keeps both cores busy (run one after the other,
        # the three used 1.2 cores on average).
        with checks.timed("student loop, autograder and mistakes (two lanes; CPU of all three)"):
            mistakes = Beside(checks, "  mistakes: the newest labs' catalogues, one entry of the others",
                              check_mistakes, labs)
            try:
                with checks.timed("  student loop (a temporary release)", concurrent=True):
                    check_student_loop(checks)
                with checks.timed("  autograder (a bundle, five submissions)", concurrent=True):
                    check_autograder(checks)
            finally:
                mistakes.join()  # its checks are recorded even if the lane beside it raised
        if sanitizing is not None:
            check_sanitize(checks, sanitizing)
    return checks.finish()
