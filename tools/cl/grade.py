"""Grader core: run one lab's graded Catch2 test cases, one process per case.

A graded case is tagged [labNN][pts=N]. Each case runs alone, so a crash or a
hang costs only that case. Results can be written as Gradescope JSON.
"""
import fnmatch
import json
import os
import re
import shlex
import signal
import subprocess
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

CASE_TIMEOUT = 120  # seconds per test case
LIST_TIMEOUT = 60  # seconds for a listing
# Characters that Catch2's test-spec parser reads as syntax, not as part of a name.
UNSELECTABLE = re.compile(r'[,\[\]*\\"]|^~|^exclude:')
PTS_TAG = re.compile(r"\[pts=([^\]]*)\]", re.IGNORECASE)
# Cases tagged [hidden] (in tests/*/hidden_*.cpp) run only in the Gradescope
# bundle (tools/cl/autograder.py) and in the honesty checks; local grading skips them.
HIDDEN_TAG = "[hidden]"
FAILURE_TAGS = ("Expression", "Exception", "FatalErrorCondition", "Failure")
# OpenMP threads that wait sleep instead of spinning: on a shared or busy
# machine a spinning barrier costs a tiny parallel sweep milliseconds, and
# 10,000 sweeps then hit the time limit. Results are the same bits. Read at
# each case, so that what a caller sets (the lanes: Wine's prefix) is passed on.
def case_env():
    return {**os.environ, "OMP_WAIT_POLICY": os.environ.get("OMP_WAIT_POLICY", "passive")}


TERMINAL_CAP = 300  # characters of one failure's reason, and of its context, on the terminal
JSON_CAP = 4000  # characters of one case's output in results.json


@dataclass
class CaseResult:
    """One graded test case: its points and, if it failed, why."""

    name: str
    points: float
    passed: bool
    reason: str = ""  # one line
    details: list = field(default_factory=list)  # CAPTUREd values etc.
    signal: int = 0  # the signal that killed the case, 0 if none
    # A failed expression in parts, for a terminal line that keeps what matters
    # when it must be cut: the source text, Catch2's expansion, file:line.
    parts: tuple = ()
    skipped: str = ""  # why the case did not run here (it then neither scores nor counts)

    @property
    def score(self):
        return self.points if self.passed else 0


@dataclass
class LabResult:
    """The graded cases of one lab, plus problems with the tests themselves."""

    lab: str
    cases: list = field(default_factory=list)
    errors: list = field(default_factory=list)  # one line each

    @property
    def score(self):
        return sum(case.score for case in self.cases)

    @property
    def max_score(self):
        return sum(case.points for case in self.cases if not case.skipped)

    @property
    def passed(self):
        return [case for case in self.cases if case.passed]

    @property
    def failed(self):
        return [case for case in self.cases if not case.passed and not case.skipped]

    @property
    def skipped(self):
        return [case for case in self.cases if case.skipped]


def lab_id(lab):
    """`lab01_single_spring` -> `lab01`."""
    return lab.split("_", 1)[0]


def lab_tag(lab):
    """`lab01_single_spring` -> `[lab01]`, the tag of its graded cases."""
    return f"[{lab_id(lab)}]"


def test_runner():
    """The command a test program runs under, from CL_TEST_RUNNER (split as a
    shell would; [] when unset): every listing and every case is then
    `RUNNER... BINARY ARGS`. The MinGW lane sets `wine` to grade a Windows
    build on Linux (tools/cl/lanes.py)."""
    return shlex.split(os.environ.get("CL_TEST_RUNNER", ""))


class ListingError(Exception):
    """A test program crashed or hung while listing its cases."""


def fmt_points(value):
    """Points without a trailing `.0`."""
    return f"{value:g}"


def case_filter(pattern):
    """A predicate on case names for `-t PATTERN`: a Catch2-style wildcard (`*`)
    or else a case-insensitive substring; None selects everything."""
    if not pattern:
        return None
    if "*" in pattern or "?" in pattern:
        return lambda name: fnmatch.fnmatchcase(name.lower(), pattern.lower())
    return lambda name: pattern.lower() in name.lower()


def source_points(test_dir, tag):
    """Total [pts=N] of the TEST_CASEs tagged `tag` in test_dir/*.cpp: the most a
    lab can score, known even when its tests do not compile."""
    total = 0.0
    for source in sorted(Path(test_dir).glob("*.cpp")):
        text = source.read_text(encoding="utf-8")
        for tags in re.findall(r'TEST_CASE\s*\(\s*"(?:[^"\\]|\\.)*"\s*,\s*"([^"]*)"', text):
            if tag.lower() in tags.lower() and HIDDEN_TAG not in tags.lower():
                for spelling in PTS_TAG.findall(tags):
                    try:
                        total += float(spelling)
                    except ValueError:
                        pass
    return int(total) if total.is_integer() else total


def grade_lab(lab, binary, root, select=None, hidden=False, skip_tags=None):
    """Run every case of `binary` tagged with the lab's tag (and accepted by
    `select`, a predicate on names; the [hidden] ones only when `hidden`);
    return a LabResult. `skip_tags` maps a tag to why its cases cannot run in
    this build ({"[openmp]": "..."} without OpenMP): they are reported as
    skipped, never run, never failed."""
    result = LabResult(lab)
    if not binary.is_file():
        result.errors.append(f"{relative(binary, root)} not found (is {lab} added in CMakeLists.txt?)")
        return result
    tag = lab_tag(lab)
    try:
        names = list_names(binary, tag)
        points = case_points(binary, tag, names, result.errors)
        if not hidden:
            skipped = set(list_names(binary, tag + HIDDEN_TAG))
            names = [name for name in names if name not in skipped]
        cannot_run = {}
        for skip_tag, why in (skip_tags or {}).items():
            cannot_run.update((name, why) for name in list_names(binary, tag + skip_tag))
    except ListingError as error:
        result.errors.append(f"{relative(binary, root)}: {error}")
        return result
    if not names:
        result.errors.append(f"{relative(binary, root)} has no test case tagged {tag}")
    if select is not None:
        names = [name for name in names if select(name)]
    with tempfile.TemporaryDirectory(prefix="cl-grade-") as work:
        for name in names:
            unselectable = UNSELECTABLE.search(name)
            if unselectable:
                result.errors.append(
                    f'{tag} test case "{name}" cannot be selected by name in Catch2 '
                    f"(because of '{unselectable.group()}'); rename the TEST_CASE")
            elif name in cannot_run:
                result.cases.append(CaseResult(name, points.get(name, 0), False, skipped=cannot_run[name]))
            elif name in points:
                result.cases.append(run_case(binary, name, points[name], Path(work), root))
    return result


def catch_list(binary, *args, stderr=False):
    """Output lines of a Catch2 listing (its exit code is a count, not a status);
    stderr: its stderr's lines too."""
    try:
        done = subprocess.run([*test_runner(), str(binary), *args], capture_output=True, encoding="utf-8", errors="replace",
                              timeout=LIST_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        raise ListingError(f"listing timed out after {LIST_TIMEOUT} s") from None
    except OSError as error:
        raise ListingError(f"cannot run ({error.strerror})") from None
    if done.returncode < 0:
        raise ListingError(f"crashed (signal {-done.returncode}) while listing its tests")
    return [line.strip() for line in (done.stdout + (done.stderr if stderr else "")).splitlines() if line.strip()]


_NAMES_ONLY = {}  # binary -> the flags that list names only: Catch2 2.x's, or 3.x's


def names_only_flags(binary):
    """Catch2 2.x lists bare names with --list-test-names-only; 3.x dropped the
    flag (Debian 13, Ubuntu 24.04, Homebrew, MSYS2 ship only 3.x) for
    --list-tests at quiet verbosity."""
    key = str(binary)
    if key not in _NAMES_ONLY:
        said = catch_list(binary, "--list-test-names-only", "[cl-probe-no-such-tag]", stderr=True)
        v3 = any("Unrecognised token" in line and "--list-test-names-only" in line for line in said)
        _NAMES_ONLY[key] = ["--list-tests", "--verbosity", "quiet"] if v3 else ["--list-test-names-only"]
    return _NAMES_ONLY[key]


def list_names(binary, spec=None):
    """Names of the test cases matching `spec` (None: every case), in declaration order."""
    names = catch_list(binary, *names_only_flags(binary), *([spec] if spec is not None else []))
    # Catch2 quotes names that start with '#' in this listing.
    return [n[1:-1] if n.startswith('"#') and n.endswith('"') else n for n in names]


def case_points(binary, tag, names, errors):
    """Map name -> points from the [pts=N] tags; report cases with none or several."""
    found = {}
    for line in catch_list(binary, "--list-tags", tag):
        for spelling in PTS_TAG.findall(line):
            try:
                value = float(spelling)
            except ValueError:
                errors.append(f"{tag} tag [pts={spelling}] is not a number")
                continue
            value = int(value) if value.is_integer() else value
            for name in list_names(binary, f"{tag}[pts={spelling}]"):
                found.setdefault(name, []).append(value)
    points = {}
    for name in names:
        values = found.get(name, [])
        if len(values) == 1:
            points[name] = values[0]
        else:
            problem = "has no [pts=N] tag" if not values else "has several [pts=N] tags"
            errors.append(f'{tag} test case "{name}" {problem}')
    return points


def run_case(binary, name, points, work, root):
    """Run one case in its own process (cwd `work`) and judge it."""
    report = work / "report.xml"
    report.unlink(missing_ok=True)
    try:
        # -o relative to the cwd: a program run through a runner may not read
        # the host's absolute path as one of its own (Wine: a Windows path).
        done = subprocess.run([*test_runner(), str(binary), name, "-r", "xml", "-o", report.name], cwd=work,
                              env=case_env(),
                              capture_output=True, timeout=CASE_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        return CaseResult(name, points, False, f"timed out after {CASE_TIMEOUT} s")
    if done.returncode < 0:
        number = -done.returncode
        return CaseResult(name, points, False, f"crashed (signal {number}, {signal_name(number)})",
                          signal=number)
    test_case = read_test_case(report, name)
    if test_case is None:
        return CaseResult(name, points, False, f"exit code {done.returncode} with no result")
    outcome = test_case.find("OverallResult")
    if outcome is not None and outcome.get("skips", "0") != "0":  # Catch2 3's SKIP (exit code 4)
        skip = test_case.find(".//Skip")
        why = " ".join((skip.text or "").split()) if skip is not None else "skipped by the test"
        return CaseResult(name, points, False, skipped=why)
    if outcome is not None and outcome.get("success") == "true":
        if done.returncode == 0:
            return CaseResult(name, points, True)
        return CaseResult(name, points, False, f"exit code {done.returncode} after the case passed")
    reason, details, parts = first_failure(test_case, root)
    return CaseResult(name, points, False, reason, details, parts=parts)


def signal_name(number):
    try:
        return signal.Signals(number).name
    except ValueError:
        return "unknown signal"


def read_test_case(report, name):
    """The <TestCase> element for `name` in a Catch2 XML report, or None."""
    try:
        tree = ET.parse(report)
    except (OSError, ET.ParseError):
        return None
    return next((tc for tc in tree.iter("TestCase") if tc.get("name") == name), None)


def first_failure(test_case, root):
    """(one-line reason, context, parts) for the first failure in a <TestCase>;
    the context lists INFO messages before CAPTUREd values (`name := value`),
    so that a cut drops the captures first."""
    infos = []
    for element in test_case.iter():
        if element.tag == "Info":
            infos.append(text_of(element))
        elif element.tag in FAILURE_TAGS and element.get("success") != "true":
            reason, parts = describe(element, root)
            captured = [info for info in infos if " := " in info]
            return reason, [info for info in infos if " := " not in info] + captured, parts
        elif element.tag == "Expression":
            infos = []
    return "failed without a failing assertion in the report", [], ()


def describe(element, root):
    """(one line, parts) for a failing <Expression>, <Exception>, <Failure> or
    fatal error; parts is (check, expansion, file:line) for an expression."""
    exception = element if element.tag == "Exception" else element.find("Exception")
    if exception is not None:
        return text_of(exception), ()
    where = location(element, root)
    if element.tag != "Expression":
        return f"{text_of(element)} ({where})", ()
    original = text_of(element.find("Original"))
    expanded = text_of(element.find("Expanded"))
    check = f"{element.get('type', 'CHECK')}( {original} )"
    if not expanded or expanded == original:
        expanded = ""
    line = f"{check} with {expanded} ({where})" if expanded else f"{check} ({where})"
    return line, (check, expanded, where)


def terminal_reason(case, limit=None):
    """A failed case's reason in about `limit` characters for the terminal: what
    was found (Catch2's expansion: actual, expected, tolerance, where in the
    matrix or mesh) and the file:line are kept; the check's source text is cut
    first, then the end of the expansion."""
    limit = limit or TERMINAL_CAP
    if len(case.reason) <= limit or not case.parts or not case.parts[1]:
        return clip(case.reason, limit)
    check, expanded, where = case.parts
    tail = f" ({where})"
    room = limit - len(tail)
    if len(expanded) + len(" with ") + 16 <= room:  # the whole expansion, the check's text cut
        keep = room - len(expanded) - len(" with ") - len("... )")
        return f"{check[:keep]}... ) with {expanded}{tail}"
    return f"{expanded[:room - 3]}...{tail}"  # the expansion alone, cut at its end


def location(element, root):
    return f"{relative(Path(element.get('filename', '?')), root)}:{element.get('line', '?')}"


def text_of(element):
    """An element's text on one line."""
    return " ".join("".join(element.itertext()).split()) if element is not None else ""


def relative(path, root):
    """`path` relative to `root` when it lies inside it."""
    try:
        return str(Path(path).relative_to(root))
    except ValueError:
        return str(path)


def clip(text, limit, note="see build/grade/results.json"):
    """`text` cut to about `limit` characters, saying how much was cut."""
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... [{len(text) - limit} more characters; {note}]"


def context_line(case):
    """A failing case's CAPTUREd / INFO context on one line, or ""."""
    return "with " + "; ".join(case.details) if case.details else ""


def case_output(case):
    """The text a student sees for one case in Gradescope."""
    if case.passed:
        return "passed"
    if case.skipped:
        return f"skipped: {case.skipped}"
    lines = [case.reason, *(f"with {info}" for info in case.details)]
    return clip("\n".join(lines), JSON_CAP, "cut by the grader")


def write_gradescope(path, labs):
    """Write Gradescope's results.json for a list of LabResult."""
    tests = [{"name": f"{lab_id(lab.lab)}: {case.name}",
              "score": case.score,
              "max_score": 0 if case.skipped else case.points,
              "output": case_output(case),
              "visibility": "visible"}
             for lab in labs for case in lab.cases]
    tests += [{"name": f"{lab_id(lab.lab)}: test error", "score": 0, "max_score": 0,
               "output": error, "visibility": "visible"}
              for lab in labs for error in lab.errors]
    results = {"score": sum(lab.score for lab in labs),
               "max_score": sum(lab.max_score for lab in labs),
               "tests": tests}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")


# ---------------------------------------------------------------- sanitizer reports

SANITIZER_ERROR = re.compile(r"==\d+==ERROR: (\w+Sanitizer): (.*)")
UBSAN_ERROR = re.compile(r"^(\S+?):(\d+):\d+: runtime error: (.*)$")
ASSERTION = re.compile(r"(Assertion .* failed\.?)")
# The usual causes, named next to the sanitizer's words (handouts: Troubleshooting).
SANITIZER_HINTS = [
    (("null pointer", "SEGV on unknown address 0x0000"), " (a matrix or vector written before it was sized?)"),
    (("heap-buffer-overflow", "out of bounds", "stack-buffer-overflow"), " (an index past the end?)"),
]
# A frame's file is absolute, or relative to the build tree where the compiler
# ran when ccache rewrote the paths under CCACHE_BASEDIR (GCC 14 keeps them so).
FRAME = re.compile(r"#\d+ 0x[0-9a-f]+ in (.*?) ((?:/|\.\./|\./)\S+?):(\d+)(?::\d+)?$")


def sanitizer_report(text, root):
    """What a sanitizer run printed, in at most three lines: the error, and the
    first stack frames that lie in the course tree (the student's file first)."""
    headline = None
    for line in text.splitlines():
        line = line.strip()
        for pattern, form in ((SANITIZER_ERROR, "{1}"), (UBSAN_ERROR, "{2}"), (ASSERTION, "{0}")):
            match = pattern.search(line)
            if match and headline is None:
                headline = form.format(*match.groups())
                headline = re.sub(r" on (unknown )?address 0x[0-9a-f]+.*", r"", headline)
                if pattern is UBSAN_ERROR and inside(path := in_tree(match.group(1), root), root):
                    return [f"{headline} at {relative(path, root)}:{match.group(2)}"]
    frames = []
    for line in text.splitlines():
        match = FRAME.search(line.strip())
        if match and inside(path := in_tree(match.group(2), root), root):
            frames.append((relative(path, root), match.group(3), match.group(1)))
    if headline is None and not frames:
        return []
    hint = next((h for words, h in SANITIZER_HINTS if headline and any(w in headline for w in words)), "")
    lines = [f"sanitizer: {headline or 'a report without a headline'}{hint}"]
    student = next((f for f in frames if f[0].startswith(("labs/", "solutions/"))), None)
    for frame in dict.fromkeys(f for f in (student, frames[0] if frames else None) if f):
        function = re.sub(r"\(.*", "", frame[2])
        lines.append(f"at {frame[0]}:{frame[1]} (in {function})")
    return lines


def in_tree(path, root):
    """A sanitizer's file name as a path: a relative one is relative to the build
    tree the compiler ran in (CL_BUILD_DIR, default build/ of `root`)."""
    if os.path.isabs(path):
        return path
    build = Path(os.environ.get("CL_BUILD_DIR", "build"))
    return os.path.normpath((build if build.is_absolute() else Path(root) / build) / path)


def inside(path, root):
    try:
        Path(path).resolve().relative_to(Path(root).resolve())
        return True
    except (ValueError, OSError):
        return False
