"""./course handouts: every command a handout shows runs in its week's tree.

A handout (labs/labNN_name/README.md) is read by a student with the release of
week NN and nothing else (docs/DESIGN.md §4). Each command it shows, in a code
block or in `backticks`, is checked against that tree without building it: the
week's tree follows release_files()'s rule (the stubs of every lab, the
references of the labs before NN), and a lab's executable is asked with
--check (docs/DESIGN.md §3), which parses the flags and loads the scenes as the
run would and writes nothing. The README's commands are checked in the week of
the latest lab they name.

A command fails when the week's tree would refuse it: a reference the week has
not got (labNN_solution in week NN), a later week's lab, a flag or a scene
refused, `./course plots` or `./course view` pointed at a folder no earlier
command of the page writes, a `-t PATTERN` that matches no graded case, or a
command that needs every lab's reference (the bench) shown without saying it
is the instructor's.
"""
import argparse
import re
import shlex
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from . import grade
from .base import ROOT, CourseError
from .base import program as executable_path
from .build import BuildFailure, build_targets, configure
from .demo import demo_folders
from .labs import demo_lines, lab_dirs, manifest, resolve_lab
from .release import is_release

# Commands that need every lab's reference or the instructor's tree: a handout
# shows them only as the instructor's (the word within INSTRUCTOR_LINES above).
INSTRUCTOR_COMMANDS = {"bench", "extremes", "fuzz", "sanitize", "release", "autograder"}
INSTRUCTOR_PROGRAMS = re.compile(r"^(trade|extremes|bench_\w+)$")
INSTRUCTOR_LINES = 4
STUDENT_COMMANDS = {"setup", "demo", "test", "help", "run", "live", "grade", "plots", "view", "claims"}
INSTRUCTOR_COMMANDS |= {"mistakes", "handouts"}
# A usage line, not a command: a placeholder in capitals (DIR, PATTERN, ARGS) or labNN.
TEMPLATE = re.compile(r"\b(labNN\w*|[A-Z]{2,}[A-Z0-9_]*)\b|…|\.\.\.")
COMMAND = re.compile(r"^(\./course\s|build/bin/|lab\d\d_[a-z0-9_]+\s)")
CHECK_SECONDS = 30


@dataclass
class Command:
    line: int           # 1-based line in the page
    text: str
    instructor: bool    # the page says it is the instructor's


@dataclass
class PageResult:
    page: str
    week: int
    checked: int = 0
    problems: list = field(default_factory=list)

    def summary(self):
        where = f"week {self.week:02d}'s tree" if self.week else "their weeks' trees"
        return f"{self.page}: {self.checked - len(self.problems)}/{self.checked} commands run in {where}"


def page_commands(path):
    """The commands a page shows: indented or fenced code lines and inline code
    spans that start with ./course or build/bin/ (comments and `\\` joins undone)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found = []
    fenced = False
    pending = None
    heading = ""
    for number, raw in enumerate(lines, 1):
        if raw.startswith("#") and not fenced:
            heading = raw.lower()
        if raw.lstrip().startswith("```"):
            fenced = not fenced
            continue
        block = fenced or raw.startswith("    ")
        candidates = [raw.strip()] if block else re.findall(r"`([^`]+)`", raw)
        for text in candidates:
            if pending is not None:
                text = pending + " " + text
                pending = None
            elif not COMMAND.match(text):
                continue
            text = re.sub(r"\s+#.*$", "", text).strip()
            if text.endswith("\\"):
                pending = text[:-1].strip()
                continue
            context = " ".join(lines[max(0, number - 1 - INSTRUCTOR_LINES):number]).lower()
            found.append(Command(number, text, "instructor" in context or "instructor" in heading))
    return found


def lab_number(name):
    match = re.match(r"lab(\d\d)", name)
    return int(match.group(1)) if match else None


class Week:
    """What the release of week `week` holds, read from the lab list: the stubs
    of every lab, the references of the labs before it."""

    def __init__(self, week):
        self.week = week

    def program(self, token):
        """(the executable in build/bin, None) or (None, why the week has none)."""
        solution = token.endswith("_solution")
        try:
            lab = resolve_lab(token.removesuffix("_solution"))
        except CourseError as error:
            return None, str(error)
        number = lab_number(lab)
        if number > self.week:
            return None, f"{token}: lab {number:02d} is a later week's (this page is week {self.week:02d})"
        if solution and number >= self.week:
            return None, (f"{token}: week {self.week:02d}'s tree has no reference of lab {number:02d} "
                          f"(use lab{number:02d}, the student's own code)")
        return lab + ("_solution" if solution else ""), None


def check_program(program, args):
    """Run PROGRAM ARGS --check from the course root; the problem, or None."""
    path = executable_path(program)
    if not path.is_file():
        return f"{program} is not built"
    try:
        done = subprocess.run([str(path), "--check", *args], cwd=ROOT, capture_output=True,
                              encoding="utf-8", errors="replace",
                              timeout=CHECK_SECONDS, check=False)
    except subprocess.TimeoutExpired:
        return f"--check ran past {CHECK_SECONDS} s (a path that does not stop at its start)"
    if done.returncode != 0 or "check: ok" not in done.stdout:
        lines = done.stderr.strip().splitlines() or done.stdout.strip().splitlines() or ["(no output)"]
        return f"--check exit {done.returncode}: {lines[-1]}"
    return None


def flag_value(args, flag):
    for i, arg in enumerate(args):
        if arg == flag and i + 1 < len(args):
            return args[i + 1]
        if arg.startswith(flag + "="):
            return arg.split("=", 1)[1]
    return None


class PageChecker:
    """Checks one page's commands in order: an earlier command's --out is what a
    later plots or view may read."""

    def __init__(self, week):
        self.week = Week(week)
        self.outs = []  # (folder, with --frames) written by earlier commands, relative to ROOT
        self.demo_out = None  # where an earlier plain `./course demo` wrote

    def check(self, command):
        try:
            words = shlex.split(command.text)
        except ValueError as error:
            return f"does not parse as a shell command ({error})"
        if re.fullmatch(r"lab\d\d_[a-z0-9_]+", words[0]):
            return f"{words[0]} is not a command in the student's tree: write ./course run {words[0][:5]} ..."
        if words[0].startswith("build/bin/"):
            return self.check_binary(command, words[0][len("build/bin/"):], words[1:])
        if len(words) < 3 and words[1:] != ["demo"]:
            return None  # `./course live` named in a sentence, or ./course alone: its usage
        sub, rest = words[1], words[2:]
        if sub in INSTRUCTOR_COMMANDS:
            return None if command.instructor else f"./course {sub} needs every lab's reference: say it is the instructor's"
        if sub not in STUDENT_COMMANDS:
            return f"./course has no command '{sub}'"
        return getattr(self, f"check_{sub}", lambda _rest: None)(rest)

    def check_binary(self, command, name, args):
        if INSTRUCTOR_PROGRAMS.match(name):
            if not command.instructor:
                return f"build/bin/{name} needs every lab's reference: say it is the instructor's"
            return None if name.startswith("bench_") else check_program(name, args)
        program, why = self.week.program(name)
        return why or self.run_checked(program, args)

    def run_checked(self, program, args):
        problem = check_program(program, args)
        out = flag_value(args, "--out")
        if problem is None and out:
            self.outs.append((Path(out), flag_value(args, "--frames") is not None))
        return problem

    def check_run(self, rest):
        if not rest or rest[0].startswith("-"):
            return "./course run needs a lab"
        program, why = self.week.program(rest[0])
        return why or self.run_checked(program, rest[1:])

    def check_live(self, rest):
        rest = [word for word in rest if word != "--bench" and not word.startswith("--port=")]  # live's own
        if "--port" in rest:
            index = rest.index("--port")
            del rest[index:index + 2]
        if not rest:
            return "./course live needs a lab"
        program, why = self.week.program(rest[0])
        return why or check_program(program, [*rest[1:], "--live"])

    def check_grade(self, rest):
        parser = argparse.ArgumentParser(add_help=False)
        parser.add_argument("labs", nargs="*")
        parser.add_argument("-t")
        parser.add_argument("-v", action="store_true")
        parser.add_argument("--solutions", action="store_true")
        parser.add_argument("--output")
        try:
            args = parser.parse_args(rest)
        except SystemExit:
            return "./course grade refuses these arguments"
        for token in args.labs:
            program, why = self.week.program(token + ("_solution" if args.solutions else ""))
            if why:
                return why
            if args.t and not matching_cases(resolve_lab(token), args.t):
                return f"-t {args.t}: matches no graded case of {token}"
        return None

    def check_demo(self, rest):
        """`./course demo` writes out/labMM_name/ for the labs with a reference
        in the week (MM < NN); `./course demo labMM` that lab's with the
        student's code, each of its demo.txt runs checked (--check)."""
        parser = argparse.ArgumentParser(add_help=False)
        parser.add_argument("labs", nargs="*")
        parser.add_argument("--out", default="out")
        parser.add_argument("--quick", action="store_true")
        try:
            args = parser.parse_args(rest)
        except SystemExit:
            return "./course demo refuses these arguments"
        if not args.labs:
            self.demo_out = Path(args.out)
            return None
        for token in args.labs:
            program, why = self.week.program(token)
            if why:
                return why
            lab = resolve_lab(token.removesuffix("_solution"))
            if not demo_lines(lab):
                return f"{token} has no demo (labs/{lab}/demo.txt)"
            lab_out = Path(args.out) / lab
            for line in demo_lines(lab):
                problem = check_program(program, [a.replace("{out}", str(lab_out)) for a in line])
                if problem:
                    return f"labs/{lab}/demo.txt: {shlex.join(line)}: {problem}"
            self.outs.append((lab_out, False))
            self.outs += [(lab_out / folder, True) for folder in demo_folders(lab, frames_only=True)]
        return None

    def demo_writes(self, folder, frames=False):
        """True for a folder that `./course demo`, shown earlier on the page,
        fills in this week: out/ itself, or out/labMM_name/... of a lab with
        a reference in the week (MM < NN), a folder its demo.txt writes
        (with frames: one that keeps a trajectory)."""
        if self.demo_out is None or folder == self.demo_out:
            return folder == self.demo_out
        parts = folder.relative_to(self.demo_out).parts if is_under(folder, self.demo_out) else ()
        if not parts or not re.fullmatch(r"lab\d\d_\w+", parts[0]) or lab_number(parts[0]) >= self.week.week:
            return False
        return not frames or "/".join(parts[1:]) in demo_folders(parts[0], frames_only=True)

    def check_plots(self, rest):
        targets = [t for t in rest if not t.startswith("-")]
        labs = [t for t in targets if re.fullmatch(r"lab\d\d(_\w+)?", t)]
        folders = [Path(t) for t in targets if t not in labs]
        folder = folders[0] if folders else Path("out")
        if re.fullmatch(r"lab\d\d_\w+", folder.name):
            roots = [folder]
        else:
            roots = [folder / resolve_lab(lab) for lab in labs] or [folder]
        for root in roots:
            if not any(is_under(out, root) or is_under(root, out) for out, _ in self.outs) \
                    and not self.demo_writes(root):
                return (f"./course plots reads {root}/, where no earlier command of this page writes in "
                        f"week {self.week.week:02d}'s tree (give --out {root}/..., or ./course demo "
                        f"lab{self.week.week:02d} first)")
        return None

    def check_view(self, rest):
        folders = []
        skip = False
        for word in rest:
            if skip or word == "--output":
                skip = not skip
                continue
            folders.append(Path(word))
        for folder in folders:
            if not any(out == folder and frames for out, frames in self.outs) \
                    and not self.demo_writes(folder, frames=True):
                return f"./course view {folder}: no earlier command of this page writes a trajectory there (--frames N --out {folder})"
        return None


def is_under(path, root):
    return path == root or root in path.parents


_CASES = {}


def matching_cases(lab, pattern):
    """The lab's graded cases that `./course grade LAB -t PATTERN` would run."""
    if lab not in _CASES:
        # The student's and the reference's programs hold the same cases (compiled once, linked twice).
        _CASES[lab] = grade.list_names(executable_path(f"{lab}_tests"), grade.lab_tag(lab))
    selected = grade.case_filter(pattern)
    return [name for name in _CASES[lab] if selected(name)]


def points_problems(lab, page):
    """The handout's point totals ("## Your task (N points[, and H hidden])",
    "Score: X/N") against the grader's: the [pts=N] tags of the lab's graded
    cases, listed from its test program as ./course grade lists them."""
    program, tag = executable_path(f"{lab}_tests"), grade.lab_tag(lab)
    if not program.is_file():
        return [f"{program.name} is not built"]
    errors = []
    totals = []
    for spec in (f"{tag}~[hidden]", f"{tag}[hidden]"):
        names = grade.list_names(program, spec)
        totals.append(sum(grade.case_points(program, tag, names, errors).values()))
    visible, hidden = (grade.fmt_points(total) for total in totals)
    problems = list(errors)
    for match in re.finditer(r"## Your task \((\d+) points?(?:, and (\d+) hidden)?\)", page):
        # A week's tree has no hidden case (the autograder's): a page that
        # does not name them is not wrong about them.
        if match.group(1) != visible or match.group(2) not in (None, hidden):
            problems.append(f"'{match.group(0)}': the graded cases give {visible} points, and {hidden} hidden")
    for match in re.finditer(r"Score: X/(\d+)", page):
        if match.group(1) != visible:
            problems.append(f"'Score: X/{match.group(1)}': the graded cases give {visible} points")
    return problems


def todo_problems(lab, page):
    """The stub's TODO comments ("TODO(lab12.5) [4 pts]", or "[with lab06.4:
    2 pts]" for two functions graded together) against the handout's task
    table: a row's points go to the TODOs its first cell names, a row with an
    empty first cell to the row above; rows of whole steps ("all five") and
    joint rows no TODO names are the table's own."""
    todo = {}
    for path in sorted((ROOT / "labs" / lab).glob("*.cpp")):
        for match in re.finditer(r"TODO\((lab\d+\.\d+)\) \[(?:with (lab\d+\.\d+): )?(\d+) pts?\]",
                                 path.read_text(encoding="utf-8")):
            if match.group(2):  # "[with lab06.4: 2 pts]": both TODOs name the same joint points
                todo[" + ".join(sorted(match.group(1, 2)))] = int(match.group(3))
            else:  # one TODO may be split over functions (lab13.5's two comments)
                todo[match.group(1)] = todo.get(match.group(1), 0) + int(match.group(3))
    table, key = {}, None
    rows = re.search(r"\n## [^\n]*[Tt]ask[^\n]*\n(?:[^|\n][^\n]*\n|\n)*((?:\|[^\n]*\n)+)", page)
    for row in (rows.group(1).splitlines()[2:] if rows else []):
        cells = [cell.strip() for cell in row.strip().strip("|").split("|")]
        if cells[0]:
            key = " + ".join(sorted(re.findall(r"lab\d+\.\d+", cells[0]))) or None
        if key and len(cells) > 2 and cells[2].isdigit():
            table[key] = table.get(key, 0) + int(cells[2])
    return [f"TODO({key}) in labs/{lab}/ gives {todo.get(key, 'no')} points, the task table {table.get(key, 'none')}"
            for key in sorted(set(todo) | {key for key in table if " + " not in key or key in todo})
            if todo.get(key) != table.get(key)]


def check_page(path, week):
    result = PageResult(str(path.relative_to(ROOT)), week)
    checker = PageChecker(week)
    for command in page_commands(path):
        if TEMPLATE.search(command.text):
            # A usage line is not run, but the programs it names must be in the week's tree.
            for token in re.findall(r"\blab\d\d(?:_[a-z0-9_]+)?\b", command.text):
                why = Week(week).program(token)[1] if week else None
                if why and not command.instructor:
                    result.problems.append(f"line {command.line}: {command.text}\n            {why}")
            continue
        # The README's: the first week whose tree holds what the command names
        # (labNN_solution: the week after NN's).
        named = [int(n) + bool(solution) for n, solution in re.findall(r"\blab(\d\d)\w*?(_solution)?\b", command.text)]
        page_week = week or max(named or [1])
        checker.week = Week(page_week)
        result.checked += 1
        problem = checker.check(command)
        if problem:
            result.problems.append(f"line {command.line}: {command.text}\n            {problem}")
    return result


def needed_targets(labs):
    targets = []
    for lab in labs:
        targets += [lab, f"{lab}_tests"]
        if manifest().get(lab, {}).get("reference"):
            targets.append(f"{lab}_solution")
    return targets + ["trade", "extremes"]


# The pages outside the labs whose commands a reader copies: the README and the
# pages it sends readers to (DESIGN.md's usage lines are its contracts, not commands).
FRONT_PAGES = [ROOT / "README.md", ROOT / "docs" / "views.md", ROOT / "docs" / "instructor.md",
               ROOT / "docs" / "testing.md"]


def check_handouts(labs):
    """One PageResult per lab's handout (and, with every lab, the README's and
    its docs pages', FRONT_PAGES)."""
    results = [check_page(ROOT / "labs" / lab / "README.md", lab_number(lab)) for lab in labs]
    for lab, result in zip(labs, results):  # and its point totals, as one more check
        result.checked += 1
        page = (ROOT / "labs" / lab / "README.md").read_text(encoding="utf-8")
        result.problems += [f"points: {problem}" for problem in points_problems(lab, page) + todo_problems(lab, page)]
    if set(labs) == set(lab_dirs()):
        results += [check_page(page, 0) for page in FRONT_PAGES]
    return results


def cmd_handouts(argv):
    parser = argparse.ArgumentParser(prog="course handouts",
                                     description="check that every command of each lab's handout runs in "
                                                 "its week's tree (by --check; nothing is written)")
    parser.add_argument("labs", nargs="*", metavar="labNN", help="the labs (default: all, README.md and the docs pages it links)")
    args = parser.parse_args(argv)
    labs = [resolve_lab(token) for token in args.labs] or lab_dirs()
    if is_release():
        # It checks every week's tree from the instructor's (every reference,
        # the bench's programs): as ./course bench, one line, exit 2.
        raise CourseError("./course handouts is the instructor's: it checks each handout against its week's "
                          "tree from the instructor's, which holds every lab's reference and the bench's "
                          "programs (this is a student release)", code=2)
    configure()
    try:
        build_targets(needed_targets(labs), log=None)
    except BuildFailure as failure:
        raise CourseError(str(failure), details=failure.lines) from None
    failed = 0
    for result in check_handouts(labs):
        print(f"handouts {result.summary()}")
        for problem in result.problems:
            print(f"  FAIL {problem}")
        failed += bool(result.problems)
    return 1 if failed else 0
