"""./course fuzz: the scene loader and the live mode's message parser under
libFuzzer (fuzz/, clang), and its CI check."""
import argparse
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from .base import BUILD, ROOT, CourseError, show
from .build import BuildFailure, build_targets, generator_args, quiet

REGRESSIONS = ROOT / "tests" / "common" / "scene_regressions"
LIVE_REGRESSIONS = ROOT / "tests" / "common" / "live_regressions"
# Each target: its seeds (besides its saved inputs), dictionary and regression
# folder. They fuzz at the same time, one core each: the machine has two.
TARGETS = {
    "fuzz_scene": (lambda: ROOT.glob("labs/*/scenes/*.json"), ROOT / "fuzz" / "scene.dict", REGRESSIONS),
    "fuzz_live": (lambda: [], ROOT / "fuzz" / "live.dict", LIVE_REGRESSIONS),
}
CI_SECONDS = 30  # ./course test: 30 s on each of the two cores, the minute of one core the loader had alone


def build_fuzzer(log=sys.stdout):
    """Build fuzz/ with clang++ into BUILD/fuzz; return the fuzz_scene program
    (fuzz_live beside it)."""
    fuzz_build = BUILD / "fuzz"
    if shutil.which("clang++") is None:
        raise CourseError("clang++ not found (Debian and Ubuntu: apt-get install clang libclang-rt-dev)", code=2)
    if not (fuzz_build / "CMakeCache.txt").is_file():
        quiet(["cmake", "-S", str(ROOT / "fuzz"), "-B", str(fuzz_build), *generator_args(fuzz_build),
               "-DCMAKE_CXX_COMPILER=clang++",
               "-DCMAKE_BUILD_TYPE=RelWithDebInfo"], "configure fuzz/")
    build_targets(list(TARGETS), build_dir=fuzz_build, log=log)
    return fuzz_build / "fuzz_scene"


def fuzz_one(program, seconds):
    """Fuzz with PROGRAM (a target of TARGETS, built) for SECONDS on one core,
    from its seeds and saved inputs, with its dictionary. A crashing input is
    copied into the target's regression folder. (ok, libFuzzer's last lines, copied inputs)."""
    seeds, dictionary, regressions = TARGETS[program.name]
    fuzz_build = program.parent
    suffix = "" if program.name == "fuzz_scene" else f"-{program.name}"  # the scene fuzzer's folders as before
    corpus = fuzz_build / f"corpus{suffix}"
    corpus.mkdir(exist_ok=True)
    for seed in [*seeds(), *(p for p in regressions.glob("*") if p.name != "README.md")]:
        shutil.copy(seed, corpus / f"seed-{seed.name}")
    artifacts = fuzz_build / f"crashes{suffix}"
    shutil.rmtree(artifacts, ignore_errors=True)
    artifacts.mkdir()
    done = subprocess.run([str(program), f"-max_total_time={seconds}", "-rss_limit_mb=2048",
                           "-max_len=4096" if program.name == "fuzz_scene" else "-max_len=5000",
                           f"-dict={dictionary}", f"-artifact_prefix={artifacts}/", str(corpus)],
                          cwd=fuzz_build, capture_output=True, encoding="utf-8", errors="replace", check=False)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    kept = []
    for artifact in sorted(artifacts.iterdir()):
        target = regressions / artifact.name
        shutil.copy(artifact, target)
        kept.append(target)
    return done.returncode == 0, lines[-12:], kept


def fuzz(program, seconds):
    """Fuzz every target of TARGETS (PROGRAM, build_fuzzer's, and the others beside
    it) at the same time, one core each, for SECONDS. Return (ok, the last lines of
    each run's output, the copied inputs)."""
    ok, lines, kept = True, [], []
    with ThreadPoolExecutor(max_workers=len(TARGETS)) as pool:
        runs = list(pool.map(lambda name: fuzz_one(program.parent / name, seconds), TARGETS))
    for name, (one_ok, one_lines, one_kept) in zip(TARGETS, runs):
        ok = ok and one_ok
        shown = one_lines if not one_ok else [line for line in one_lines if line.startswith("Done ")][-1:]
        lines += [f"{name}: {line}" for line in shown]
        kept += one_kept
    return ok, lines, kept


def run_fuzz(seconds, log=sys.stdout):
    """Build the fuzzer and fuzz for SECONDS: fuzz()'s (ok, lines, kept)."""
    return fuzz(build_fuzzer(log), seconds)


def cmd_fuzz(argv):
    parser = argparse.ArgumentParser(prog="course fuzz")
    parser.add_argument("seconds", nargs="?", type=int, default=60,
                        help="how long to fuzz, each target on its own core (default 60)")
    args = parser.parse_args(argv)
    ok, lines, kept = run_fuzz(args.seconds)
    for line in lines:
        print(line)
    if ok:
        print("fuzz: no crash")
        return 0
    for path in kept:
        print(f"fuzz: a crashing input, kept as a regression test: {show(path)}")
    print("fuzz: fix the loader (or the live parser) until ./course test passes, then commit the input with the fix")
    return 1


def check_fuzz(checks, seconds=CI_SECONDS):
    """CI: build the fuzzer, then start its run in the background (a core per target, SECONDS);
    return a function that waits for it and records the check (None when the build
    failed, which is recorded at once). ./course test waits for it at once: the
    fuzzers need their cores to themselves (checks.py)."""
    try:
        with checks.timed("fuzz: build (clang)"):
            program = build_fuzzer(log=None)
    except (CourseError, BuildFailure) as error:
        checks.record(False, f"fuzz the scene loader: {error}")
        return None
    started = time.monotonic()
    pool = ThreadPoolExecutor(max_workers=1)
    running = pool.submit(fuzz, program, seconds)

    def finish():
        try:
            ok, lines, kept = running.result()
        except (CourseError, OSError) as error:
            checks.record(False, f"fuzz the scene loader: {error}")
            return
        finally:
            pool.shutdown()
            checks.add_time(f"fuzz: {seconds} s run", time.monotonic() - started)
        runs = "; ".join(line for line in lines if "Done " in line)
        details = [] if ok else [*lines, *(f"kept as a regression test: {show(path)}" for path in kept)]
        checks.record(ok, f"fuzz the scene loader and the live parser for {seconds} s each, at once: "
                      f"{runs or 'no summary'}",
                      details)
    return finish
