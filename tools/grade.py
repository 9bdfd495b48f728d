"""Grader core: run one lab's graded Catch2 test cases, one process per case.

A graded case is tagged [labNN][pts=N]. Each case runs alone, so a crash or a
hang costs only that case. Results can be written as Gradescope JSON.
"""
import json
import re
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
FAILURE_TAGS = ("Expression", "Exception", "FatalErrorCondition", "Failure")


@dataclass
class CaseResult:
    """One graded test case: its points and, if it failed, why."""

    name: str
    points: float
    passed: bool
    reason: str = ""  # one line
    details: list = field(default_factory=list)  # CAPTUREd values etc.

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
        return sum(case.points for case in self.cases)

    @property
    def passed(self):
        return [case for case in self.cases if case.passed]

    @property
    def failed(self):
        return [case for case in self.cases if not case.passed]


def lab_id(lab):
    """`lab01_single_spring` -> `lab01`."""
    return lab.split("_", 1)[0]


def lab_tag(lab):
    """`lab01_single_spring` -> `[lab01]`, the tag of its graded cases."""
    return f"[{lab_id(lab)}]"


class ListingError(Exception):
    """A test program crashed or hung while listing its cases."""


def fmt_points(value):
    """Points without a trailing `.0`."""
    return f"{value:g}"


def grade_lab(lab, binary, root):
    """Run every case of `binary` tagged with the lab's tag; return a LabResult."""
    result = LabResult(lab)
    if not binary.is_file():
        result.errors.append(f"{relative(binary, root)} not found (is {lab} added in CMakeLists.txt?)")
        return result
    tag = lab_tag(lab)
    try:
        names = list_names(binary, tag)
        points = case_points(binary, tag, names, result.errors)
    except ListingError as error:
        result.errors.append(f"{relative(binary, root)}: {error}")
        return result
    if not names:
        result.errors.append(f"{relative(binary, root)} has no test case tagged {tag}")
    with tempfile.TemporaryDirectory(prefix="cl-grade-") as work:
        for name in names:
            unselectable = UNSELECTABLE.search(name)
            if unselectable:
                result.errors.append(
                    f'{tag} test case "{name}" cannot be selected by name in Catch2 '
                    f"(because of '{unselectable.group()}'); rename the TEST_CASE")
            elif name in points:
                result.cases.append(run_case(binary, name, points[name], Path(work), root))
    return result


def catch_list(binary, *args):
    """Output lines of a Catch2 listing (its exit code is a count, not a status)."""
    try:
        done = subprocess.run([str(binary), *args], capture_output=True, text=True,
                              timeout=LIST_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        raise ListingError(f"listing timed out after {LIST_TIMEOUT} s") from None
    except OSError as error:
        raise ListingError(f"cannot run ({error.strerror})") from None
    if done.returncode < 0:
        raise ListingError(f"crashed (signal {-done.returncode}) while listing its tests")
    return [line.strip() for line in done.stdout.splitlines() if line.strip()]


def list_names(binary, spec):
    """Names of the test cases matching `spec`, in declaration order."""
    names = catch_list(binary, "--list-test-names-only", spec)
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
        done = subprocess.run([str(binary), name, "-r", "xml", "-o", str(report)],
                              cwd=work, capture_output=True, timeout=CASE_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        return CaseResult(name, points, False, f"timed out after {CASE_TIMEOUT} s")
    if done.returncode < 0:
        number = -done.returncode
        return CaseResult(name, points, False, f"crashed (signal {number}, {signal_name(number)})")
    test_case = read_test_case(report, name)
    if test_case is None:
        return CaseResult(name, points, False, f"exit code {done.returncode} with no result")
    outcome = test_case.find("OverallResult")
    if outcome is not None and outcome.get("success") == "true":
        if done.returncode == 0:
            return CaseResult(name, points, True)
        return CaseResult(name, points, False, f"exit code {done.returncode} after the case passed")
    reason, details = first_failure(test_case, root)
    return CaseResult(name, points, False, reason, details)


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
    """(one-line reason, CAPTUREd values) for the first failure in a <TestCase>."""
    infos = []
    for element in test_case.iter():
        if element.tag == "Info":
            infos.append(text_of(element))
        elif element.tag in FAILURE_TAGS and element.get("success") != "true":
            return describe(element, root), infos
        elif element.tag == "Expression":
            infos = []
    return "failed without a failing assertion in the report", []


def describe(element, root):
    """One line for a failing <Expression>, <Exception>, <Failure> or fatal error."""
    exception = element if element.tag == "Exception" else element.find("Exception")
    if exception is not None:
        return text_of(exception)
    where = location(element, root)
    if element.tag != "Expression":
        return f"{text_of(element)} ({where})"
    original = text_of(element.find("Original"))
    expanded = text_of(element.find("Expanded"))
    check = f"{element.get('type', 'CHECK')}( {original} )"
    if expanded and expanded != original:
        check += f" with {expanded}"
    return f"{check} ({where})"


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


def case_output(case):
    """The text a student sees for one case in Gradescope."""
    if case.passed:
        return "passed"
    return "\n".join([case.reason, *(f"with {info}" for info in case.details)])


def write_gradescope(path, labs):
    """Write Gradescope's results.json for a list of LabResult."""
    tests = [{"name": f"{lab_id(lab.lab)}: {case.name}",
              "score": case.score,
              "max_score": case.points,
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
    path.write_text(json.dumps(results, indent=2) + "\n")
