"""./course sanitize: the whole test suite under ASan and UBSan (build/asan), and its CI check."""
import argparse
import subprocess
import sys
import tempfile
import time

from . import grade
from .base import BUILD, ROOT, CourseError
from .build import BuildFailure, build_targets, configure, quiet, sanitizer_env
from .labs import manifest

SANITIZE_BUILD = BUILD / "asan"


def sanitize_targets():
    """The whole test suite: common_tests and every lab's graded tests on its reference."""
    labs = [lab for lab, entry in manifest().items() if entry["reference"]]
    return ["common_tests", *(f"{lab}_tests_solution" for lab in labs)]


def run_sanitized(log=sys.stdout):
    """Build the test suite with -fsanitize=address,undefined (CMakeLists.txt: CL_SANITIZE)
    into BUILD/asan and run every test program there, every case (hidden ones too).
    Return [(program, ok, summary line, report lines)]."""
    return run_programs(build_sanitized(log))


def build_sanitized(log=sys.stdout):
    """Configure (once) and build the sanitizer build's test programs; return their names."""
    configure(log=log)  # labs.json says which labs have a reference
    # Without precompiled headers: under -fsanitize and -g1 a file that loads
    # the header takes twice as long as one that parses its own includes
    # (12.3 s against 5.9 s of CPU for a lab 06 test file).
    if not (SANITIZE_BUILD / "CMakeCache.txt").is_file():
        quiet(["cmake", "-S", str(ROOT), "-B", str(SANITIZE_BUILD), "-DCL_SANITIZE=ON", "-DCL_PCH=OFF",
               "-DCMAKE_BUILD_TYPE=RelWithDebInfo", "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1"],
              "configure the sanitizer build")
    targets = sanitize_targets()
    build_targets(targets, build_dir=SANITIZE_BUILD, log=log, label="the test suite (-fsanitize=address,undefined)")
    return targets


def run_programs(targets):
    """Run each sanitizer-built test program, every case: [(program, ok, summary line, report lines)]."""
    env = sanitizer_env(leaks=True)
    results = []
    for name in targets:
        start = time.monotonic()
        with tempfile.TemporaryDirectory(prefix="cl-asan-") as work:
            done = subprocess.run([str(SANITIZE_BUILD / "bin" / name)], cwd=work, env=env, capture_output=True,
                                  text=True, check=False)
        output = done.stdout + done.stderr
        report = grade.sanitizer_report(output, ROOT)
        ok = done.returncode == 0 and not report
        lines = output.splitlines()
        summary = next((line for line in reversed(lines) if "test cases" in line or "All tests passed" in line),
                       f"exit code {done.returncode}")
        results.append((name, ok, f"{summary.strip()} ({time.monotonic() - start:.1f} s)",
                        report or ([] if ok else lines[-20:])))
    return results


def cmd_sanitize(argv):
    argparse.ArgumentParser(prog="course sanitize").parse_args(argv)
    failed = 0
    for name, ok, summary, report in run_sanitized():
        print(f"{'ok  ' if ok else 'FAIL'}  {name}: {summary}")
        for line in report:
            print(f"        {line}")
        failed += not ok
    print("sanitize: clean" if not failed else f"sanitize: {failed} program(s) with findings or failures")
    return 1 if failed else 0


def check_sanitize(checks):
    """CI: the whole test suite under ASan and UBSan, clean."""
    try:
        with checks.timed("sanitize: build"):
            targets = build_sanitized(log=None)
    except (CourseError, BuildFailure) as error:
        checks.record(False, f"sanitizer build: {error}", getattr(error, "lines", getattr(error, "details", [])))
        return
    with checks.timed("sanitize: runs"):
        results = run_programs(targets)
    for name, ok, summary, report in results:
        checks.record(ok, f"{name} under ASan+UBSan: {summary}", report)
