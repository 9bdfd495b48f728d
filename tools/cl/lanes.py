"""./course lanes [libcxx] [mingw]: the course built and graded with the
toolchains of the students' other systems (docs/DESIGN.md §1, "The lanes").

libcxx  clang with libc++ and LLVM's libomp, macOS's toolchain: common, every
        lab's stubs, references and graded tests, the unit tests; every graded
        case on the references and every unit test must pass.
mingw   MinGW-w64, Windows' native toolchain, cross-built and linked
        statically: common, every lab's executables (the student's and the
        reference) and graded tests; the references of WINE_LABS graded under
        Wine through the course's own grader (CL_TEST_RUNNER, grade.py).

Each lane has its own build tree, BUILD/lanes/NAME, configured once with its
toolchain file (cmake/lanes/), built niced with Ninja and ccache (paths
relative to the tree, so that a second run, or CI's next, compiles nothing
that did not change). One line per lane says its result and its wall and CPU
time; the lines before it say what failed.
"""
import argparse
import json
import os
import shutil
import subprocess
import time

from . import grade
from .base import BUILD, ROOT, CourseError, show
from .build import first_errors

LANES = ("libcxx", "mingw")
# Debian's packages each lane needs (apt-get installs them when run as root).
PACKAGES = {"libcxx": ["clang", "libc++-dev", "libc++abi-dev", "libomp-dev", "ninja-build", "catch2"],
            "mingw": ["g++-mingw-w64-x86-64-posix", "wine", "ninja-build", "catch2", "libeigen3-dev",
                      "nlohmann-json3-dev", "libcli11-dev", "libboost-dev"]}
TOOLCHAINS = {"libcxx": "cmake/lanes/libcxx.cmake", "mingw": "cmake/lanes/mingw/toolchain.cmake"}
# Catch2 2.13 under libc++: it is header-only, where a Catch2 3 installed
# beside it is a library built against libstdc++ (CMakeLists.txt, CL_CATCH2_2).
CONFIGURE = {"libcxx": ["-DCL_CATCH2_2=ON"], "mingw": []}
# The labs graded under Wine: every lab's references, each case a Wine
# process of about a second.
WINE_LABS = "all"
WARNINGS_SHOWN = 5
NO_OPENMP = "this build has no OpenMP, so there is no parallel region to count"


class LaneFailure(Exception):
    """A lane that could not get as far as its tests: its message and the lines that say why."""

    def __init__(self, message, lines=()):
        super().__init__(message)
        self.lines = list(lines)


def missing_packages(lanes):
    """The Debian packages `lanes` need that are not installed; None without dpkg."""
    if shutil.which("dpkg-query") is None:
        return None
    missing = []
    for package in dict.fromkeys(p for lane in lanes for p in PACKAGES[lane]):
        done = subprocess.run(["dpkg-query", "-W", "-f=${Status}", package], capture_output=True,
                              encoding="utf-8", errors="replace", check=False)
        if done.stdout != "install ok installed":
            missing.append(package)
    return missing


def install(lanes):
    """Install what the lanes need, as ./course does (root: apt-get; else the line to run)."""
    missing = missing_packages(lanes)
    if missing is None:
        raise CourseError(f"the lanes need Debian's packages ({' '.join(PACKAGES[lanes[0]])}): "
                          "run them on Debian or Ubuntu, or in the dev container")
    if not missing:
        return
    if os.geteuid() != 0:
        raise CourseError(f"the lanes need: sudo apt-get install -y {' '.join(missing)}", code=2)
    log = BUILD / "lanes" / "apt.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    print(f"installing {' '.join(missing)} (log: {show(log)})", flush=True)
    with log.open("w") as out:
        for command in (["apt-get", "update"], ["apt-get", "install", "-y", *missing]):
            if subprocess.run(command, stdout=out, stderr=subprocess.STDOUT, check=False,
                              env=dict(os.environ, DEBIAN_FRONTEND="noninteractive")).returncode != 0:
                raise CourseError(f"apt-get failed, see {show(log)}")


def children_cpu():
    """CPU seconds (user + system) of the child processes waited for so far."""
    times = os.times()  # not the resource module: ./course imports this one on Windows too
    return times.children_user + times.children_system


def run_quiet(command, **kwargs):
    """Run `command`, its output captured: (exit code, output)."""
    done = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, encoding="utf-8",
                          errors="replace", check=False, **kwargs)
    return done.returncode, done.stdout


def configure(lane, build_dir):
    """Configure the lane's tree once (Ninja re-runs CMake when CMakeLists.txt changes)."""
    if (build_dir / "CMakeCache.txt").is_file():
        return
    code, output = run_quiet(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-G", "Ninja",
                              "-DCMAKE_BUILD_TYPE=Release", f"-DCMAKE_TOOLCHAIN_FILE={ROOT / TOOLCHAINS[lane]}",
                              *CONFIGURE[lane]])
    if code != 0:
        shutil.rmtree(build_dir, ignore_errors=True)  # the next run configures again
        raise LaneFailure("configure failed", output.splitlines()[-12:])


def lane_manifest(build_dir):
    return json.loads((build_dir / "labs.json").read_text(encoding="utf-8"))


def targets_of(lane, build_dir):
    """What the lane builds: only what it runs or must prove compiles."""
    labs = lane_manifest(build_dir)["labs"]
    if lane == "libcxx":
        # The stubs compiled (not linked), the references linked; the unit tests.
        targets = ["common_tests"]
        if "bench_tests" in target_names(build_dir):
            targets.append("bench_tests")
        for lab, entry in labs.items():
            targets += [f"{lab}_student"]
            if entry["reference"]:
                targets += [f"{lab}_solution", f"{lab}_tests_solution"]
        return targets
    targets = []
    for lab, entry in labs.items():
        targets += [lab, f"{lab}_tests"]
        if entry["reference"]:
            targets += [f"{lab}_solution", f"{lab}_tests_solution"]
    return targets


def target_names(build_dir):
    code, output = run_quiet(["ninja", "-C", str(build_dir), "-t", "targets", "all"])
    return {line.split(":")[0] for line in output.splitlines()} if code == 0 else set()


def build(targets, build_dir):
    """Build `targets` on both cores, niced (the machine may be shared): past a
    failure, so that one report lists every target that does not build."""
    code, output = run_quiet(["nice", "-n", "10", "cmake", "--build", str(build_dir), "-j", "2", "--target",
                              *targets, "--", "-k", "0"])
    if code != 0:
        failed = sorted({line.split()[-1] for line in output.splitlines() if line.startswith("FAILED: ")})
        raise LaneFailure(f"build failed ({len(failed)} outputs)", [*failed[:6], *first_errors(output)])
    # The tree's own warnings, each once (a header's, from every file that includes it).
    return list(dict.fromkeys(line.replace(str(ROOT) + "/", "") for line in output.splitlines()
                              if " warning: " in line and "/usr/" not in line.split(" warning: ")[0]))


def grade_references(build_dir, labs, runner=None):
    """Grade each lab's references in the lane's tree: (passed, counted, skipped, failure lines)."""
    features = lane_manifest(build_dir)["build"]
    skip = {} if features.get("openmp", True) else {"[openmp]": NO_OPENMP}
    passed = counted = skipped = 0
    lines = []
    saved = os.environ.get("CL_TEST_RUNNER")
    if runner:
        os.environ["CL_TEST_RUNNER"] = runner
    try:
        for lab in labs:
            suffix = ".exe" if runner else ""
            result = grade.grade_lab(lab, build_dir / "bin" / f"{lab}_tests_solution{suffix}", ROOT, skip_tags=skip)
            passed += len(result.passed)
            counted += len(result.cases) - len(result.skipped)
            skipped += len(result.skipped)
            lines += [f"{lab}: {error}" for error in result.errors]
            lines += [f'{lab}: "{case.name}": {grade.terminal_reason(case)}' for case in result.failed]
            if result.errors or not result.cases:
                counted += 1  # a lab that lists no case is a failure, not a pass
    finally:
        if saved is None:
            os.environ.pop("CL_TEST_RUNNER", None)
        else:
            os.environ["CL_TEST_RUNNER"] = saved
    return passed, counted, skipped, lines


def unit_tests(build_dir):
    """ctest -L unit in the lane's tree: (passed, total, failure lines)."""
    code, output = run_quiet(["ctest", "--test-dir", str(build_dir), "-L", "unit", "-j", "2", "--output-on-failure"])
    summary = next((line for line in output.splitlines() if "tests passed" in line), "")
    words = summary.split()
    total = int(words[-1]) if words and words[-1].isdigit() else 0
    failed = [line.strip() for line in output.splitlines() if "***Failed" in line or "Not Run" in line]
    return total - len(failed), total, ([] if code == 0 else failed or output.splitlines()[-12:])


WINE_VARIABLES = ("WINEPREFIX", "WINEDEBUG", "WINEDLLOVERRIDES")


def wine_environment(build_dir):
    """Wine's own prefix in the lane's tree, no debug output, no Mono or Gecko prompt."""
    return dict(os.environ, WINEPREFIX=str(build_dir / "wineprefix"), WINEDEBUG="-all",
                WINEDLLOVERRIDES="mscoree,mshtml=")


def run_lane(lane):
    """Configure, build and run one lane: (ok, summary, failure lines)."""
    build_dir = BUILD / "lanes" / lane
    configure(lane, build_dir)
    manifest = lane_manifest(build_dir)
    labs = [lab for lab, entry in manifest["labs"].items() if entry["reference"]]
    start = time.monotonic()
    warnings = build(targets_of(lane, build_dir), build_dir)
    built = f"built in {time.monotonic() - start:.0f} s"
    if warnings:
        built += f" ({len(warnings)} warnings, the first {min(len(warnings), WARNINGS_SHOWN)} above)"
        for line in warnings[:WARNINGS_SHOWN]:
            print(f"        {line}")
    if lane == "libcxx":
        passed, counted, skipped, lines = grade_references(build_dir, labs)
        unit_passed, unit_total, unit_lines = unit_tests(build_dir)
        ok = passed == counted and not lines and unit_passed == unit_total and not unit_lines
        summary = (f"{passed}/{counted} graded cases on the references of {len(labs)} labs"
                   f"{f' ({skipped} skipped)' if skipped else ''}, unit tests {unit_passed}/{unit_total}; {built}")
        return ok, summary, lines + unit_lines
    graded = labs if WINE_LABS == "all" else [lab for lab in labs if grade.lab_id(lab) in WINE_LABS]
    env = wine_environment(build_dir)
    # The grader's processes inherit os.environ: Wine's variables go there
    # for the lane's time (the lanes run last, one after the other).
    saved = {key: os.environ.get(key) for key in WINE_VARIABLES}
    os.environ.update({key: env[key] for key in WINE_VARIABLES})
    try:
        # The first run makes the prefix. Then one wineserver for the whole
        # lane (-p: it stays between the cases' processes), stopped at the end,
        # and Wine's background services (winedevice.exe and the like) started
        # under it with their output on /dev/null: a service inherits the
        # standard handles of the program whose start launched it, and one
        # launched by a graded program whose output the grader reads holds
        # that pipe open as long as the persistent server lives, so the read
        # never ends (CI, 2026-12-07: the lane's first captured run hung for
        # its whole timeout; reproduced with `wine prog 2>&1 | cat`).
        quiet = dict(env=env, cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                     stderr=subprocess.DEVNULL, check=False)
        # `wineserver -p` while the first run's server lingers fails (exit 2)
        # and leaves none persistent: every graded program then boots Wine's
        # services again, seconds each. So: wait for that server to end first.
        subprocess.run(["wine", "cmd", "/c", "exit"], timeout=600, **quiet)
        subprocess.run(["wineserver", "-w"], timeout=600, **quiet)
        if subprocess.run(["wineserver", "-p"], timeout=60, **quiet).returncode != 0:
            raise LaneFailure("wineserver -p did not start a persistent Wine server", [])
        subprocess.run(["wine", "cmd", "/c", "exit"], timeout=600, **quiet)
        passed, counted, skipped, lines = grade_references(build_dir, graded, runner="wine")
    finally:
        subprocess.run(["wineserver", "-k"], env=env, check=False)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    ok = passed == counted and not lines
    # Wine runs each program outside the lane's process tree (its processes
    # are wineserver's), so their CPU is not in the lane's CPU time.
    summary = (f"{passed}/{counted} graded cases on the references of {len(graded)} labs under Wine"
               f"{f' ({skipped} skipped: no OpenMP)' if skipped else ''}; {built}; CPU without Wine's programs")
    return ok, summary, lines


def cmd_lanes(argv):
    parser = argparse.ArgumentParser(prog="course lanes")
    parser.add_argument("lanes", nargs="*", metavar="LANE", help=f"{', '.join(LANES)} (default: both)")
    args = parser.parse_args(argv)
    unknown = [lane for lane in args.lanes if lane not in LANES]
    if unknown:
        raise CourseError(f"unknown lane {unknown[0]} (lanes: {', '.join(LANES)})", code=2)
    lanes = list(dict.fromkeys(args.lanes)) or list(LANES)
    install(lanes)
    # ccache keys each compile on paths relative to the tree, as in ./course test.
    os.environ.setdefault("CCACHE_BASEDIR", str(ROOT))
    failed = 0
    for lane in lanes:
        start, cpu = time.monotonic(), children_cpu()
        try:
            ok, summary, lines = run_lane(lane)
        except LaneFailure as failure:
            ok, summary, lines = False, str(failure), failure.lines
        except subprocess.TimeoutExpired as error:
            ok, summary, lines = False, f"timed out: {' '.join(error.cmd)}", []
        for line in lines:
            print(f"        {line}")
        print(f"{'ok  ' if ok else 'FAIL'}  lane {lane}: {summary}; {time.monotonic() - start:.0f} s, "
              f"{children_cpu() - cpu:.0f} s of CPU", flush=True)
        failed += not ok
    return 1 if failed else 0

