"""./course sanitize: the whole test suite under ASan and UBSan (build-asan), and its CI check;
then lab 04's reference in live mode under the round-3 attacks (tools/cl/live_hostile.py:
check_hostile), whose server must stay clean too."""
import argparse
import atexit
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
import os
from pathlib import Path
import signal
import subprocess
import sys
import tempfile
import threading
import time

from . import grade
from .base import BUILD, ROOT, CourseError
from .build import (BuildFailure, build_command, build_targets, configure, first_errors, generator_args, quiet,
                    sanitizer_env)
from .labs import manifest

# Beside BUILD, not inside it: at the same depth under the course's root, its
# compile lines are the main build's once ccache makes paths relative to the
# root (./course test), so the test programs' own files, compiled alike in both
# (CMakeLists.txt: CL_SANITIZE), are compiled once.
SANITIZE_BUILD = BUILD.parent / f"{BUILD.name}-asan"

# The CPU seconds of the background's processes, each reaped by os.wait4, so
# that ./course test's table can count them apart from the foreground steps'.
_background = {"cpu": 0.0}
_background_lock = threading.Lock()


def background_cpu():
    """CPU seconds (user + system) of the background suite's finished processes."""
    with _background_lock:
        return _background["cpu"]


def wait_counted(process):
    """Wait for `process` (a Popen) with os.wait4 and count its CPU, and its
    children's, as the background's; return its exit code."""
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    with _background_lock:
        _background["cpu"] += usage.ru_utime + usage.ru_stime
    return process.returncode


SANITIZE_LIVE = "lab04_pbd_solution"  # the live server's attacks run on it (check_hostile)


def sanitize_targets():
    """The whole test suite: common_tests and every lab's graded tests on its reference."""
    labs = [lab for lab, entry in manifest().items() if entry["reference"]]
    return ["common_tests", *(f"{lab}_tests_solution" for lab in labs)]


def run_sanitized(log=sys.stdout):
    """Build the test suite with -fsanitize=address,undefined (CMakeLists.txt: CL_SANITIZE)
    into SANITIZE_BUILD and run every test program there, every case (hidden ones too).
    Return [(program, ok, summary line, report lines)], the live attacks last."""
    return run_programs(build_sanitized(log)) + [run_live()]


def configure_sanitized(log=sys.stdout):
    """Configure the sanitizer build (when new or its flags changed); return its test programs' names."""
    configure(log=log)  # labs.json says which labs have a reference
    # A Release build; CMakeLists.txt (CL_SANITIZE) gives the course's code its flags.
    cache = SANITIZE_BUILD / "CMakeCache.txt"
    text = cache.read_text(encoding="utf-8") if cache.is_file() else ""
    if "CL_SANITIZE:BOOL=ON" not in text or "CMAKE_BUILD_TYPE:STRING=Release" not in text:
        quiet(["cmake", "-S", str(ROOT), "-B", str(SANITIZE_BUILD), *generator_args(SANITIZE_BUILD),
               "-DCL_SANITIZE=ON", "-DCMAKE_BUILD_TYPE=Release"],
              "configure the sanitizer build")
    return sanitize_targets()


def build_sanitized(log=sys.stdout):
    """Configure (once) and build the sanitizer build's test programs; return their names."""
    targets = configure_sanitized(log)
    build_targets([*targets, SANITIZE_LIVE], build_dir=SANITIZE_BUILD, log=log,
                  label=f"the test suite and {SANITIZE_LIVE} (-fsanitize=address,undefined)")
    return targets


class BackgroundSuite:
    """The sanitizer build's compile and then its runs, started now and waited
    for at the end (./course test runs them beside its other checks). Niced,
    so that those checks keep the cores they use; paused (SIGSTOP) while a
    check needs the cores to itself (the fuzzers); stopped if ./course test
    ends first."""

    def __init__(self):
        self.gate = threading.Event()  # set: the background may run
        self.gate.set()
        self.lock = threading.Lock()
        self.running = set()  # the sanitizer-built programs running now
        self.targets = configure_sanitized(log=None)
        self.build_seconds = self.build_cpu = None
        self.run_seconds = self.run_cpu = None
        self.results = None
        self.error = None
        self.output = tempfile.TemporaryFile(mode="w+", encoding="utf-8")
        self.started = time.monotonic()
        # The instrumented libraries first; the test programs once the main
        # build is done (main_built): their own files are the main build's
        # (CMakeLists.txt: CL_SANITIZE), and ccache hands them over, where a
        # test batch reached first would be compiled twice (with both at work,
        # labs 07-14's were: 640 s of CPU for this build instead of about 330 s).
        libraries = ["common", *(f"{lab}_reference" for lab, entry in manifest().items() if entry["reference"])]
        self.phases = [build_command(libraries, SANITIZE_BUILD),
                       build_command([*self.targets, SANITIZE_LIVE], SANITIZE_BUILD)]
        self.main_built = threading.Event()
        self.process = self.start_build(self.phases[0])
        atexit.register(self.stop)
        self.thread = threading.Thread(target=self.work, daemon=True)
        self.thread.start()

    def start_build(self, command):
        # A process group of its own (send and stop signal the whole build), but
        # not a session of its own: where the kernel groups processes by session
        # for scheduling (autogroup, on by default in Debian's kernels), a new
        # session gets as much CPU as all of ./course test's, and `nice` counts
        # only inside it. So started, this niced build took one of the two cores
        # from the main build (2026-12-06: the main build 297 s for 415 s of CPU).
        # (Python before 3.11 has no process_group: a session, as before.)
        group = dict(process_group=0) if sys.version_info >= (3, 11) else dict(start_new_session=True)
        return subprocess.Popen(["nice", "-n", "10", *command], cwd=ROOT, stdout=self.output,
                                stderr=subprocess.STDOUT, encoding="utf-8", errors="replace", **group)

    def start_second_phase(self):
        """The build's second phase, which becomes the build's process (send reaches it)."""
        self.process = self.start_build(self.phases[1])
        return self.process

    def work(self):
        try:
            code = wait_counted(self.process)
            if code == 0:
                self.main_built.wait()
                code = wait_counted(self.when_free(self.start_second_phase))
            self.build_seconds = time.monotonic() - self.started
            self.build_cpu = background_cpu()
            self.output.seek(0)
            text = self.output.read()
            self.output.close()
            if code != 0:
                raise BuildFailure(self.targets, first_errors(text))
            start = time.monotonic()
            self.results = run_programs(self.targets, nice=True, suite=self) + [run_live(nice=True)]
            self.run_seconds = time.monotonic() - start
            self.run_cpu = background_cpu() - self.build_cpu
        except BaseException as error:  # handed to finish(), in the main thread
            self.error = error

    def stop(self):
        if self.process.returncode is None:
            os.killpg(self.process.pid, signal.SIGTERM)

    def send(self, number):
        """Send `number` to the build (its process group, then the compilers
        ninja runs, each in a group of its own) or to the programs running."""
        build = []
        if self.process.returncode is None:
            try:
                os.killpg(self.process.pid, number)  # ninja first: stopped, it starts no compiler
            except ProcessLookupError:
                pass
            # Stopping ninja alone left the compilers it had started running
            # beside the fuzzers (ninja gives each one a process group of its own).
            build = descendants(self.process.pid)
        for pid in [*build, *(process.pid for process in self.running)]:
            try:
                os.kill(pid, number)
            except ProcessLookupError:
                pass

    @contextmanager
    def paused(self):
        """Stop the background for the duration (SIGSTOP, then SIGCONT); no
        program of it starts meanwhile."""
        with self.lock:
            self.gate.clear()
            self.send(signal.SIGSTOP)
        try:
            yield
        finally:
            with self.lock:
                self.send(signal.SIGCONT)
                self.gate.set()

    def when_free(self, launch):
        """launch() under the lock once the background may run (not while paused); its result."""
        while True:
            self.gate.wait()
            with self.lock:
                if self.gate.is_set():
                    return launch()

    def start(self, command, **options):
        """Popen(command) once the background may run, counted among those running."""
        def launch():
            process = subprocess.Popen(command, **options)
            self.running.add(process)
            return process
        return self.when_free(launch)

    def finish(self):
        """Wait for the build and the runs; return [(program, ok, summary line,
        report lines)] or raise what stopped them (BuildFailure for the build)."""
        self.thread.join()
        if self.error is not None:
            raise self.error
        return self.results


def descendants(pid):
    """The processes under `pid` (children, theirs, ...), from /proc; [] where there is none."""
    children = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text(encoding="utf-8", errors="replace")
        except OSError:  # ended meanwhile
            continue
        parent = int(text[text.rfind(")") + 2:].split()[1])  # after "pid (name) state"
        children.setdefault(parent, []).append(int(stat.parent.name))
    found, waiting = [], [pid]
    while waiting:
        for child in children.get(waiting.pop(), []):
            found.append(child)
            waiting.append(child)
    return found


def run_programs(targets, nice=False, suite=None):
    """Run each sanitizer-built test program, every case: [(program, ok, summary line, report lines)],
    two programs at a time (each runs on one core), niced when `nice`, in `suite`
    (a BackgroundSuite) when given."""
    with ThreadPoolExecutor(max_workers=2) as pool:
        return list(pool.map(lambda name: run_program(name, nice, suite), targets))


def run_program(name, nice=False, suite=None):
    """Run one sanitizer-built test program: (program, ok, summary line, report lines)."""
    # OpenMP's waiting threads sleep instead of spinning: two programs run at
    # once here, niced beside ./course test's own, so a spinning thread mostly
    # burns the core its partner needs (the suite's runs took 563 s of CPU
    # beside the foreground, 344 s alone). What is checked is unchanged.
    env = dict(sanitizer_env(leaks=True), OMP_WAIT_POLICY="passive")
    start = time.monotonic()
    command = [*(["nice", "-n", "10"] if nice else []), str(SANITIZE_BUILD / "bin" / name)]
    with tempfile.TemporaryDirectory(prefix="cl-asan-") as work, \
            tempfile.TemporaryFile(mode="w+", encoding="utf-8") as log:
        options = dict(cwd=work, env=env, stdout=log, stderr=subprocess.STDOUT, encoding="utf-8", errors="replace")
        if suite is None:
            code = subprocess.Popen(command, **options).wait()
        else:
            process = suite.start(command, **options)
            code = wait_counted(process)
            with suite.lock:
                suite.running.discard(process)
        log.seek(0)
        output = log.read()
    report = grade.sanitizer_report(output, ROOT)
    ok = code == 0 and not report
    lines = output.splitlines()
    summary = next((line for line in reversed(lines) if "test cases" in line or "All tests passed" in line),
                   f"exit code {code}")
    return (name, ok, f"{summary.strip()} ({time.monotonic() - start:.1f} s)",
            report or ([] if ok else lines[-20:]))


def run_live(nice=False):
    """SANITIZE_LIVE built with the sanitizers, live, under check_hostile's attacks (about 10 s):
    (name, ok, summary line, report lines). The ping flood's memory and rate are not asked there
    (ASan's own memory and pace); a sanitizer report from any of its programs fails it."""
    name = f"{SANITIZE_LIVE} --live"
    try:
        import websocket  # noqa: F401  (Debian's python3-websocket, which the attacks' honest page uses)
    except ImportError:
        return name, True, "skipped: python3-websocket is not installed (./course installs it)", []
    from .live_hostile import IDLE_SOCKETS, check_hostile
    start = time.monotonic()
    program = SANITIZE_BUILD / "bin" / SANITIZE_LIVE
    with tempfile.TemporaryDirectory(prefix="cl-asan-live-") as work:
        problems, numbers = check_hostile(program, work, start_seconds=60, bounded=False, env=sanitizer_env(leaks=True),
                                          prefix=["nice", "-n", "10"] if nice else [])
    report = grade.sanitizer_report(numbers.get("stderr", ""), ROOT)
    ok = not problems and not report
    return (name, ok, f"names cut inside a character, refused heads, RFC answers, hidden controls, {IDLE_SOCKETS} idle "
                      f"sockets, a ping flood, SIGINT and stop during a 1e8-iteration step ({time.monotonic() - start:.1f} s)",
            report + problems)


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


def start_sanitize(checks):
    """CI: start the sanitizer build and its runs in the background; None if it could not be configured."""
    try:
        with checks.timed("sanitize: configure"):
            return BackgroundSuite()
    except CourseError as error:
        checks.record(False, f"sanitizer build: {error}", error.details)
        return None


def check_sanitize(checks, background):
    """CI: the whole test suite under ASan and UBSan, clean; `background` is the
    BackgroundSuite start_sanitize started."""
    try:
        with checks.timed("sanitize: waiting for its build and runs"):
            try:
                results = background.finish()
            finally:
                checks.add_time("sanitize: build (in the background, niced)", background.build_seconds or 0.0,
                                concurrent=True, cpu=background.build_cpu)
                checks.add_time("sanitize: runs (in the background, niced)", background.run_seconds or 0.0,
                                concurrent=True, cpu=background.run_cpu)
    except BuildFailure as error:
        checks.record(False, f"sanitizer build: {error}", error.lines)
        return
    for name, ok, summary, report in results:
        checks.record(ok, f"{name} under ASan+UBSan: {summary}", report)
