"""Configure and build.

One configure, then per-lab builds: `./course grade lab01` builds only the
targets lab 01's grading needs, so a compile error in another lab blocks
nothing else.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

from . import grade
from .base import BUILD, CONFIG, ROOT, CourseError, program
from .labs import manifest, manifest_stale
from .requirements import INSTALLED_STAMP, cmake_hints

ERROR_LINES = 14  # of a failed build, shown
WARNING_LINES = 3  # of the warnings in a student's files, shown


class BuildFailure(Exception):
    """Targets that did not build; `lines` is the compiler's first errors."""

    def __init__(self, targets, lines):
        super().__init__(f"{' '.join(targets)} did not build")
        self.lines = lines


def generator_args(build_dir):
    """`-G Ninja` for a new build tree when ninja is installed (./course installs
    it), nothing otherwise: Ninja starts a file's compile as soon as the files
    it includes exist, where CMake's Makefiles wait for every library a target
    links, and it checks an unchanged tree in a fraction of a second instead of
    make's few seconds (an edit-grade loop pays that each time). An existing
    tree keeps the generator it was made with (CMake refuses a change)."""
    if (build_dir / "CMakeCache.txt").is_file() or shutil.which("ninja") is None:
        return []
    return ["-G", "Ninja"]


def uses_ninja(build_dir):
    cache = build_dir / "CMakeCache.txt"
    return cache.is_file() and "CMAKE_GENERATOR:INTERNAL=Ninja\n" in cache.read_text(encoding="utf-8")


def installed_since_configure(build_dir):
    """True when ./course installed packages after build_dir was configured
    (requirements.INSTALLED_STAMP): its cache still holds what was missing
    then, and Ninja re-runs CMake only when a CMakeLists.txt changes."""
    stamp, cache = build_dir / INSTALLED_STAMP, build_dir / "CMakeCache.txt"
    return stamp.is_file() and cache.is_file() and stamp.stat().st_mtime >= cache.stat().st_mtime


def configure(log=sys.stdout, force=False):
    """Configure BUILD when it is new, its lab manifest is out of date, or
    packages were installed since."""
    if force or not (BUILD / "CMakeCache.txt").is_file() or manifest_stale() or installed_since_configure(BUILD):
        print("configuring...", end=" ", file=log, flush=True)
        start = time.monotonic()
        try:
            quiet(["cmake", "-S", str(ROOT), "-B", str(BUILD), *generator_args(BUILD), "-DCMAKE_BUILD_TYPE=Release",
                   *cmake_hints()], "configure")
        finally:
            print(f"{time.monotonic() - start:.1f} s", file=log, flush=True)


def build(log=sys.stdout):
    """Configure (first time) and build everything; show the output only on failure."""
    configure(log)
    print("building...", end=" ", file=log, flush=True)
    start = time.monotonic()
    try:
        quiet(["cmake", "--build", str(BUILD), "-j", "2"], "build")
    finally:
        print(f"{time.monotonic() - start:.1f} s", file=log, flush=True)


def quiet(command, what):
    try:
        done = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, encoding="utf-8", errors="replace", check=False)
    except FileNotFoundError:
        raise CourseError(f"{command[0]} not found; ./course installs it") from None
    if done.returncode != 0:
        raise CourseError(f"{what} failed (cmake exit code {done.returncode})",
                          details=done.stdout.splitlines())


def defined_targets(build_dir=None):
    """The targets this build defines (a week's tree defines no trade, extremes
    or bench_* whose references it has not got); None when it cannot tell."""
    build_dir = build_dir or BUILD
    if not uses_ninja(build_dir):
        return None
    done = subprocess.run(["ninja", "-C", str(build_dir), "-t", "targets", "all"], capture_output=True,
                          encoding="utf-8", errors="replace", check=False)
    if done.returncode != 0:
        return None
    return {line.split(":", 1)[0].rsplit("/", 1)[-1] for line in done.stdout.splitlines()}


def build_command(targets, build_dir, keep_going=False):
    """The command that builds `targets` in build_dir on both cores (keep_going: past a failure)."""
    command = ["cmake", "--build", str(build_dir), "--config", CONFIG, "-j", "2", "--target", *targets]
    if keep_going:
        command += ["--", "-k", "0"] if uses_ninja(build_dir) else ["--", "-k"]
    return command


def build_targets(targets, build_dir=None, log=sys.stdout, label=None, keep_going=False):
    """Build only `targets`; return the tools' output. Raise BuildFailure.
    keep_going: build all that can be built past a failure (-k)."""
    build_dir = build_dir or BUILD
    if log is not None:
        print(f"building {label or ' '.join(targets)}...", end=" ", file=log, flush=True)
    start = time.monotonic()
    try:
        done = subprocess.run(build_command(targets, build_dir, keep_going),
                              cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              encoding="utf-8", errors="replace",
                              check=False)
    except FileNotFoundError:
        raise CourseError("cmake not found; ./course installs it") from None
    finally:
        if log is not None:
            print(f"{time.monotonic() - start:.1f} s", file=log, flush=True)
    if done.returncode != 0:
        raise BuildFailure(targets, first_errors(done.stdout))
    return done.stdout


def first_errors(output):
    """The compiler's first errors in a build log (make's or Ninja's), paths
    relative to the root."""
    lines, command = [], False
    for line in output.splitlines():
        if command:  # Ninja prints the failed command after its FAILED: line
            command = False
            continue
        command = line.startswith("FAILED: ")
        if not (command or re.match(r"^(\[\s*\d+%\]|\[\d+/\d+\] |ninja: |gmake|make|Scanning|Consolidate|Built target)",
                                    line) or "Error 1" in line or "Error 2" in line):
            lines.append(line)
    start = next((i for i, line in enumerate(lines)
                  if re.search(r"\b(error|Error|undefined reference)\b", line)), None)
    if start is None:
        shown = lines[-ERROR_LINES:]
    else:
        # Keep the "In function ..." line that introduces the first error.
        if start > 0 and re.search(r"In (member )?function|In file included", lines[start - 1]):
            start -= 1
        shown = lines[start:start + ERROR_LINES]
    # A path relative to the build folder (ccache's base_dir in ./course test) reads from the root too.
    return [re.sub(r"(^|[\s(])\.\./(?=\w)", r"\1", from_root(line)) for line in shown]


def from_root(line):
    """A compiler's line with the tree's paths relative to it (MinGW's say C:/..., or C:\\...)."""
    for prefix in {ROOT.as_posix() + "/", str(ROOT) + os.sep}:
        line = line.replace(prefix, "")
    return line


def student_warnings(lab, output):
    """Warnings in the lab's student files: from this build's output for the
    files it recompiled, remembered from the last compile for the others."""
    cache = BUILD / "grade" / "warnings"
    cache.mkdir(parents=True, exist_ok=True)
    found = []
    for student in manifest().get(lab, {}).get("student", []):
        remembered = cache / (student.replace("/", "__") + ".txt")
        if f"CMakeFiles/{lab}_student.dir/{student}.o" in output:
            lines = [from_root(line) for line in output.splitlines()
                     if from_root(line).startswith(student + ":") and ": warning:" in line]
            remembered.write_text("".join(line + "\n" for line in lines), encoding="utf-8")
        if remembered.is_file():
            found += remembered.read_text(encoding="utf-8").splitlines()
    return found


def sanitizer_env(leaks):
    """The environment of a sanitizer run. allow_user_segv_handler=0: Catch2 may not
    take SIGSEGV/SIGABRT from the sanitizer, whose report then shows the faulting
    line, not a re-raise."""
    return dict(os.environ,
                ASAN_OPTIONS=f"detect_leaks={int(leaks)}:allow_user_segv_handler=0:handle_abort=1",
                UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")


def sanitizer_rerun(lab, case, log=sys.stdout):
    """Rerun one crashed case in NAME_tests_asan (cmake/AddLab.cmake: the tests and
    the student's code under -fsanitize=address,undefined -g -O1); lines saying
    where it failed."""
    target = f"{lab}_tests_asan"
    try:
        build_targets([target], log=log, label=f"{target} (-fsanitize=address,undefined)")
    except BuildFailure as failure:
        return ["the sanitizer build failed:", *failure.lines[:4]]
    binary = program(target)
    # A crash is what is asked about here, so leaks are not reported.
    env = sanitizer_env(leaks=False)
    with tempfile.TemporaryDirectory(prefix="cl-asan-") as work:
        try:
            done = subprocess.run([str(binary), case.name], cwd=work, env=env, capture_output=True,
                                  encoding="utf-8", errors="replace", timeout=grade.CASE_TIMEOUT, check=False)
        except subprocess.TimeoutExpired:
            return ["the sanitizer run timed out"]
    lines = grade.sanitizer_report(done.stdout + done.stderr, ROOT)
    return lines or [f"the sanitizer build ran the case without a report (exit code {done.returncode})"]
