"""./course test: everything CI checks, in the order it runs them."""
import argparse
import json
import re
import shlex
import sys
import shutil
import subprocess
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

from . import grade
from .autograder import check_autograder
from .base import BIN, BUILD, ROOT, CourseError, show
from .build import BuildFailure, build_targets, configure
from .demo import index_links, run_demos, write_index, write_views
from .fuzz import check_fuzz
from .grading import Grader, write_results
from .labs import lab_dirs, lab_targets, manifest, reject_lines
from .measure import check_measurements
from .plots import run_plots
from .release import is_release
from .sanitize import check_sanitize, start_sanitize
from .student_loop import check_student_loop
from .view import decode_positions, load_run, write_view


class Checks:
    """Counts and prints pass/fail checks, and times the steps that make them."""

    def __init__(self):
        self.passed = 0
        self.failed = 0
        self.started = time.monotonic()
        self.times = []  # (step, seconds, ran alongside other steps)

    @contextmanager
    def timed(self, step):
        start = time.monotonic()
        try:
            yield
        finally:
            self.add_time(step, time.monotonic() - start)

    def add_time(self, step, seconds, concurrent=False):
        self.times.append((step, seconds, concurrent))

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
        width = max(len(step) for step, _, _ in [*self.times, (rest, 0, False)])
        print(f"\ntiming: {total:.0f} s in all")
        for step, seconds, concurrent in self.times:
            share = "alongside" if concurrent else f"{100 * seconds / total:5.1f} %"
            print(f"  {step:<{width}}  {seconds:7.1f} s  {share}")
        counted = sum(seconds for _, seconds, concurrent in self.times if not concurrent)
        print(f"  {rest:<{width}}  {total - counted:7.1f} s  "
              f"{100 * (total - counted) / total:5.1f} %")

    def finish(self):
        """Print the timing table and `N passed, M failed`; return the exit code."""
        self.print_times()
        print(f"{self.passed} passed, {self.failed} failed")
        return 1 if self.failed else 0


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
                              cwd=ROOT, capture_output=True, text=True, check=False)
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
    listed = subprocess.run([str(BUILD / "bin" / "common_tests"), "--list-test-names-only"], cwd=ROOT,
                            capture_output=True, text=True, check=False).stdout
    known = subprocess.run(["ctest", "--test-dir", str(BUILD), "-N", "-L", "unit"], cwd=ROOT,
                           capture_output=True, text=True, check=False).stdout
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


def check_demo(checks, out, labs, student_fallback=True):
    shutil.rmtree(out, ignore_errors=True)
    try:
        run_demos(out, echo=False, labs=labs, student_fallback=student_fallback)
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
                (scratch / "bad.json").write_text(argv[i])
                argv[i] = str(scratch / "bad.json")
        before = sorted(scratch.rglob("*"))
        try:
            done = subprocess.run([str(program), *argv], cwd=scratch, capture_output=True, text=True,
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
        program = BIN / name
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


CHROMIUM_FLAGS = ["--headless", "--disable-gpu", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                  "--enable-unsafe-swiftshader", "--enable-logging=stderr", "--v=0", "--virtual-time-budget=8000",
                  "--window-size=800,600", "--hide-scrollbars"]


def open_in_chromium(chromium, page, frame, screenshot):
    """Load PAGE?frame=FRAME in headless Chromium; (body attributes, problems):
    the page's <body> data-* attributes and what went wrong (a console error,
    an uncaught exception, no DOM)."""
    url = f"file://{page.resolve()}?frame={frame}"
    try:
        done = subprocess.run([chromium, *CHROMIUM_FLAGS, f"--screenshot={screenshot}", "--dump-dom", url],
                              capture_output=True, text=True, timeout=60, check=False)
    except subprocess.TimeoutExpired:
        return {}, [f"{url}: Chromium ran past 60 s"]
    match = re.search(r"<body([^>]*)>", done.stdout)
    if not match:
        return {}, [f"{url}: no <body> in the DOM (exit {done.returncode}): {done.stderr.strip()[-300:]}"]
    attrs = {k: v.replace("&quot;", '"').replace("&amp;", "&")
             for k, v in re.findall(r'(data-[a-z-]+)="([^"]*)"', match.group(1))}
    problems = [f"{url}: console: {line.strip()[-200:]}" for line in done.stderr.splitlines()
                if "CONSOLE" in line and "Uncaught" in line]
    if "data-error" in attrs:
        problems.append(f"{url}: the page's error: {attrs['data-error']}")
    if attrs.get("data-ready") != "1":
        problems.append(f"{url}: data-ready is {attrs.get('data-ready')!r}, not 1 (no frame drawn)")
    return attrs, problems


VIEW_BACKGROUND = (0xf4, 0xf4, 0xf0)  # the page's and the renderer's clear colour (view.py, view_player.js)


def screenshot_shares(first, second):
    """(share of non-background pixels of FIRST, of SECOND, share of pixels that
    differ), over the part of the 800 × 600 screenshots where the runs are drawn."""
    from PIL import Image, ImageChops

    # The drawing alone: below the heads-up lines, above the controls, left of the colour bar.
    images = [Image.open(path).convert("RGB") for path in (first, second)]
    images = [image.crop((0, 110, image.width - 180, image.height - 60)) for image in images]
    background = VIEW_BACKGROUND
    shares = []
    for image in images:
        flat = ImageChops.difference(image, Image.new("RGB", image.size, background)).convert("L")
        shares.append(sum(flat.point(lambda v: 255 if v > 12 else 0).histogram()[255:]) / (image.width * image.height))
    changed = ImageChops.difference(*images).convert("L").point(lambda v: 255 if v > 12 else 0)
    return shares[0], shares[1], changed.histogram()[255] / (images[0].width * images[0].height)


def drawn(share):
    """A screenshot's share of non-background pixels, as a drawn view has it:
    some mesh (>= 1 %), and the renderer's cleared background around it (a
    canvas never drawn is black: 100 %)."""
    return 0.01 <= share <= 0.95


def sample_problems(attrs, runs, frames, truth=None):
    """The page's decoded sample positions against trajectory.bin decoded here
    (to 1e-9 m), and, with `truth` (run -> final positions), against the run's
    own positions to the header's max_position_error."""
    problems = []
    try:
        samples = json.loads(attrs.get("data-sample", "[]"))
    except ValueError:
        return ["data-sample is not JSON"]
    if not samples:
        return ["no data-sample"]
    for r, particle, *shown in samples:
        header, data = runs[r]
        decoded = decode_positions(header, data, frames[r])[particle]
        gap = max(abs(a - b) for a, b in zip(shown, decoded))
        if gap > 1e-9:
            problems.append(f"run {r} particle {particle}: page {shown}, file {decoded} (|d| = {gap:.3g} m)")
        if truth and r in truth:
            error = max(abs(a - b) for a, b in zip(shown, truth[r][particle]))
            bound = header["max_position_error"] * (1 + 1e-6) + 1e-12
            if error > bound:
                problems.append(f"run {r} particle {particle}: {error:.3g} m from the run's position, "
                                f"over the stated {header['max_position_error']:.3g} m")
    return problems


def view_refusal_problems(scratch):
    """./course view on a folder without a trajectory, a truncated trajectory.bin
    and a corrupt header: exit 2, one line, nothing written."""
    problems = []
    good = scratch / "a"
    cases = {"empty": "no trajectory.json", "truncated": "truncated", "corrupt": "not a trajectory"}
    for name, expected in cases.items():
        folder = scratch / name
        folder.mkdir()
        if name == "truncated":
            shutil.copy(good / "trajectory.json", folder)
            (folder / "trajectory.bin").write_bytes((good / "trajectory.bin").read_bytes()[:-5])
        if name == "corrupt":
            (folder / "trajectory.json").write_text((good / "trajectory.json").read_text()[:200])
            shutil.copy(good / "trajectory.bin", folder)
        before = sorted(folder.iterdir())
        done = subprocess.run([sys.executable, str(ROOT / "tools" / "course.py"), "view", str(folder)],
                              capture_output=True, text=True, check=False)
        lines = done.stderr.splitlines()
        if done.returncode != 2 or len(lines) != 1 or expected not in lines[0]:
            problems.append(f"view {name}: exit {done.returncode}, stderr {lines[:3]} (expected 2, one line "
                            f"saying '{expected}')")
        if sorted(folder.iterdir()) != before:
            problems.append(f"view {name}: wrote something on a refusal")
    return problems


def check_browser(checks):
    """./course view's refusals, then the view in a real browser (headless
    Chromium, software WebGL): a short lab 04 run, a two-run comparison and two
    runs of different particle counts."""
    program = BIN / "lab04_pbd_solution"
    scratch = BUILD / "test-view"
    shutil.rmtree(scratch, ignore_errors=True)
    scratch.mkdir(parents=True)
    runs = {"a": ["--scene", "curtain-8", "--iterations", "1", "--steps", "60", "--frames", "4"],
            "b": ["--scene", "curtain-8", "--iterations", "16", "--steps", "60", "--frames", "4"],
            "rope": ["--scene", "rope-50", "--steps", "40", "--frames", "5"]}
    for name, args in runs.items():
        done = subprocess.run([str(program), *args, "--out", str(scratch / name),
                               "--summary", str(scratch / f"{name}.json")],
                              capture_output=True, text=True, check=False)
        if done.returncode != 0:
            checks.record(False, f"the view's runs: {program.name} {shlex.join(args)} exited {done.returncode}",
                          done.stderr.splitlines()[-3:])
            return
    problems = view_refusal_problems(scratch)
    checks.record(not problems, "./course view refuses a folder without a trajectory, a truncated and a corrupt "
                  "one (exit 2, one line, nothing written)", problems)
    chromium = shutil.which("chromium")
    if not chromium:
        print("skip  the view in a browser: chromium is not installed (./course installs Debian's chromium "
              "when run as root; or: sudo apt-get install chromium)")
        return

    run_a = load_run(scratch / "a")
    last = run_a[0]["frame_count"] - 1
    final = json.loads((scratch / "a.json").read_text())["positions"]
    single = write_view([scratch / "a"])
    problems, shots = [], []
    for frame in (0, last):
        shot = scratch / f"a-{frame}.png"
        attrs, found = open_in_chromium(chromium, single, frame, shot)
        problems += found
        expected = {"data-frames": str(run_a[0]["frame_count"]), "data-particles": str(run_a[0]["particles"]),
                    "data-springs": str(len(run_a[0]["springs"]) // 2), "data-frame": str(frame)}
        problems += [f"frame {frame}: {k} = {attrs.get(k)!r}, the file says {v}" for k, v in expected.items()
                     if attrs.get(k) != v]
        if attrs:
            problems += sample_problems(attrs, [run_a], [frame], {0: final} if frame == last else None)
        shots.append(shot)
    if all(shot.is_file() for shot in shots):
        first, second, changed = screenshot_shares(*shots)
        if not all(drawn(share) for share in (first, second)):
            problems.append(f"a screenshot is blank: {100 * first:.2f} % and {100 * second:.2f} % of its pixels "
                            "are not background (a drawn view has some, and a cleared background around them)")
        if changed < 0.001:
            problems.append(f"the first and the last frame look the same ({100 * changed:.3f} % of pixels differ)")
    else:
        problems.append("no screenshot written")
    checks.record(not problems, f"view of a lab 04 run in headless Chromium: {last + 1} frames, positions as in "
                  "trajectory.bin and within the stated error of the run's, no console error, first and last "
                  "frame drawn and different", problems)

    problems = []
    run_b = load_run(scratch / "b")
    for names, runs_shown in ((["a", "b"], [run_a, run_b]), (["a", "rope"], [run_a, load_run(scratch / "rope")])):
        page = write_view([scratch / n for n in names], scratch / f"view-{'-'.join(names)}.html")
        shot = scratch / f"{'-'.join(names)}.png"
        attrs, found = open_in_chromium(chromium, page, last, shot)
        problems += found
        expected = {"data-runs": "2",
                    "data-particles": ",".join(str(r[0]["particles"]) for r in runs_shown),
                    "data-frames": ",".join(str(r[0]["frame_count"]) for r in runs_shown)}
        problems += [f"{'+'.join(names)}: {k} = {attrs.get(k)!r}, the files say {v}" for k, v in expected.items()
                     if attrs.get(k) != v]
        if attrs and names[1] == "b":
            problems += sample_problems(attrs, runs_shown, [last, last])
        if shot.is_file():
            share = screenshot_shares(shot, shot)[0]
            if not drawn(share):
                problems.append(f"{'+'.join(names)}: the screenshot is blank ({100 * share:.2f} %)")
    checks.record(not problems, "side-by-side views in headless Chromium: K = 1 against K = 16 (one clock), "
                  "and a curtain beside a rope (different particle counts)", problems)


def cmd_test(argv):
    argparse.ArgumentParser(prog="course test").parse_args(argv)
    checks = Checks()
    try:
        with checks.timed("configure"):
            configure()
    except CourseError as error:
        checks.record(False, str(error), error.details)
        return checks.finish()
    labs = build_labs(checks, lab_dirs())
    check_ctest(checks)
    out = BUILD / "test-demo"
    if is_release():
        print("a student release: grading your code (a score, not a check)")
        with checks.timed("grading your code"):
            report_student_score(labs)
        with_reference = [lab for lab in labs if manifest()[lab]["reference"]]
        with checks.timed("demo"):
            check_demo(checks, out, with_reference, student_fallback=False)
        with checks.timed("rejects"):
            check_rejects(checks, with_reference)
    else:
        without = [lab for lab in labs if not manifest()[lab]["reference"]]
        for lab in without:
            checks.record(False, f"{lab}: no reference in solutions/{lab}/ (the honesty check needs one)")
        labs = [lab for lab in labs if lab not in without]
        # The fuzzer runs alone: beside the honesty checks (a process per case)
        # it managed 20 k inputs in its minute instead of about 300 k, and
        # beside the sanitizer build, niced, 173 k (the two cores share caches).
        fuzzing = check_fuzz(checks)
        if fuzzing:
            fuzzing()
        # The sanitizer build compiles, then runs the suite, in the background,
        # niced, beside every check after the fuzzer's (which runs alone,
        # above): those leave a core or part of one free most of the time,
        # the student loop's and the autograder's builds too. Its results
        # are waited for last.
        sanitizing = start_sanitize(checks)
        with checks.timed("honesty: the solutions graded"):
            check_solutions(checks, labs)
        with checks.timed("honesty: the stubs graded"):
            check_stubs(checks, labs)
        with checks.timed("demo"):
            check_demo(checks, out, labs)
        with checks.timed("rejects"):
            check_rejects(checks, labs)
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
    if not is_release():
        with checks.timed("student loop (a temporary release)"):
            check_student_loop(checks)
        with checks.timed("autograder (a bundle, five submissions)"):
            check_autograder(checks)
        if sanitizing is not None:
            check_sanitize(checks, sanitizing)
    return checks.finish()
