"""./course fuzz: the scene loader under libFuzzer (fuzz/, clang), and its CI check."""
import argparse
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from .base import BUILD, ROOT, CourseError, show
from .build import BuildFailure, build_targets, generator_args, quiet

REGRESSIONS = ROOT / "tests" / "common" / "scene_regressions"


def build_fuzzer(log=sys.stdout):
    """Build fuzz/ with clang++ into BUILD/fuzz; return the fuzz_scene program."""
    fuzz_build = BUILD / "fuzz"
    if shutil.which("clang++") is None:
        raise CourseError("clang++ not found (apt-get install clang libclang-rt-14-dev)", code=2)
    if not (fuzz_build / "CMakeCache.txt").is_file():
        quiet(["cmake", "-S", str(ROOT / "fuzz"), "-B", str(fuzz_build), *generator_args(fuzz_build),
               "-DCMAKE_CXX_COMPILER=clang++",
               "-DCMAKE_BUILD_TYPE=RelWithDebInfo"], "configure fuzz/")
    build_targets(["fuzz_scene"], build_dir=fuzz_build, log=log)
    return fuzz_build / "fuzz_scene"


def fuzz(program, seconds):
    """Fuzz the scene loader with PROGRAM (build_fuzzer's) for SECONDS, on one core,
    starting from every shipped scene and saved regression input, with the scene
    format's dictionary. A crashing input is copied into tests/common/scene_regressions/.
    Return (ok, last lines of libFuzzer's output, the copied inputs)."""
    fuzz_build = program.parent
    corpus = fuzz_build / "corpus"
    corpus.mkdir(exist_ok=True)
    seeds = [*ROOT.glob("labs/*/scenes/*.json"), *(p for p in REGRESSIONS.glob("*") if p.name != "README.md")]
    for seed in seeds:
        shutil.copy(seed, corpus / f"seed-{seed.name}")
    artifacts = fuzz_build / "crashes"
    shutil.rmtree(artifacts, ignore_errors=True)
    artifacts.mkdir()
    done = subprocess.run([str(program), f"-max_total_time={seconds}", "-rss_limit_mb=2048",
                           "-max_len=4096", f"-dict={ROOT / 'fuzz' / 'scene.dict'}",
                           f"-artifact_prefix={artifacts}/", str(corpus)],
                          cwd=fuzz_build, capture_output=True, text=True, check=False)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    kept = []
    for artifact in sorted(artifacts.iterdir()):
        target = REGRESSIONS / artifact.name
        shutil.copy(artifact, target)
        kept.append(target)
    return done.returncode == 0, lines[-12:], kept


def run_fuzz(seconds, log=sys.stdout):
    """Build the fuzzer and fuzz for SECONDS: fuzz()'s (ok, lines, kept)."""
    return fuzz(build_fuzzer(log), seconds)


def cmd_fuzz(argv):
    parser = argparse.ArgumentParser(prog="course fuzz")
    parser.add_argument("seconds", nargs="?", type=int, default=60, help="how long to fuzz (default 60)")
    args = parser.parse_args(argv)
    ok, lines, kept = run_fuzz(args.seconds)
    for line in lines:
        print(line)
    if ok:
        print("fuzz: no crash")
        return 0
    for path in kept:
        print(f"fuzz: a crashing input, kept as a regression test: {show(path)}")
    print("fuzz: fix the loader until ./course test passes, then commit the input with the fix")
    return 1


def check_fuzz(checks, seconds=60):
    """CI: build the fuzzer, then start its run in the background (one core, SECONDS);
    return a function that waits for it and records the check (None when the build
    failed, which is recorded at once). ./course test waits for it at once: the
    fuzzer needs its core to itself (checks.py)."""
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
        runs = next((line for line in reversed(lines) if line.startswith("Done ")), "")
        details = [] if ok else [*lines, *(f"kept as a regression test: {show(path)}" for path in kept)]
        checks.record(ok, f"fuzz the scene loader for {seconds} s: {runs or 'no summary'}", details)
    return finish
