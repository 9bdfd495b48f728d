"""./course bench and ./course extremes: the measurements (bench/), and their CI check."""
import argparse
import csv
import math
import shlex
import subprocess
import sys

from .base import BUILD, ROOT, CourseError, under_root
from .build import BuildFailure, build_targets, configure
from . import grade
from .labs import executable, manifest
from .plots import plots_failed, run_plots
from .requirements import shown

MEASUREMENT_PLOTS = {"trade": ("bench_pareto.py", "bench_scaling.py"), "extremes": ("bench_extremes.py",)}


def run_measurement(program, args, out, echo=True):
    """Build and run bench/PROGRAM (trade or extremes) into OUT/bench.
    Return (exit code, output lines); with echo the output goes to the terminal as it comes."""
    build_targets([program], log=sys.stdout if echo else None)
    path = executable(program)
    command = [str(path), "--out", str(out / "bench"), *args]
    if echo:
        print("  " + shlex.join([path.name, *command[1:]]), flush=True)
    done = subprocess.run(command, cwd=ROOT, capture_output=not echo, encoding="utf-8", errors="replace", check=False)
    return done.returncode, [] if echo else (done.stdout + done.stderr).splitlines()


def measurement_command(program, argv):
    """./course bench | extremes [--quick] [--out DIR]: the program, then the figures."""
    parser = argparse.ArgumentParser(prog=f"course {'bench' if program == 'trade' else program}")
    parser.add_argument("--quick", action="store_true", help="the CI size (minutes, not tens of them)")
    parser.add_argument("--out", default="out", help="output directory (default out/; CSV in OUT/bench)")
    if program == "trade":
        parser.add_argument("--micro", nargs=argparse.REMAINDER,
                            help="also run the Google Benchmark programs (bench_*), ARGS pass through")
    args = parser.parse_args(argv)
    configure()
    absent = [lab for lab, entry in manifest().items() if not entry.get("reference")]
    if absent:
        raise CourseError(f"./course {parser.prog.split()[-1]} is the instructor's: it runs every lab's reference, "
                          f"and this tree has none for {grade.lab_id(absent[0])}"
                          f"{' and later labs' if len(absent) > 1 else ''} (solutions/)", code=2)
    out = under_root(args.out)
    code, _ = run_measurement(program, ["--quick"] if args.quick else [], out)
    if plots_failed(run_plots(out, names=MEASUREMENT_PLOTS[program])):
        code = max(code, 1)
    if program == "trade" and args.micro is not None:
        code = max(code, run_micro(args.micro))
    return code


def micro_targets():
    """The Google Benchmark programs: bench/bench_NAME.cpp is the target bench_NAME,
    where this build defines it (bench/CMakeLists.txt adds those whose references exist)."""
    names = sorted(path.stem for path in (ROOT / "bench").glob("bench_*.cpp"))
    return [name for name in names if (BUILD / "bench" / "CMakeFiles" / f"{name}.dir").is_dir()]


def run_micro(argv):
    targets = micro_targets()
    if not targets:
        raise CourseError("no Google Benchmark program in this build (bench/bench_*.cpp need "
                          "libbenchmark-dev and the labs' references)")
    build_targets(targets)
    failed = []
    for name in targets:
        print(f"== {name}", flush=True)
        if subprocess.run([str(executable(name)), *argv], cwd=ROOT, check=False).returncode != 0:
            failed.append(name)
    if failed:
        raise CourseError(f"failed: {' '.join(failed)}")
    return 0


def cmd_bench(argv):
    return measurement_command("trade", argv)


def cmd_extremes(argv):
    return measurement_command("extremes", argv)


def check_measurements(checks, out):
    """CI: the quick trade and extremes runs (extremes fails on any silent NaN)."""
    for program in ("trade", "extremes"):
        try:
            with checks.timed(f"measurements: {program} --quick (build and run)"):
                code, lines = run_measurement(program, ["--quick"], out, echo=False)
        except (CourseError, BuildFailure) as error:
            checks.record(False, f"{program} --quick: {error}")
            continue
        checks.record(code == 0, f"{program} --quick: {lines[-1] if lines else 'no output'}",
                      [] if code == 0 else lines[-20:])
        if program == "trade" and code == 0:
            check_trade_accuracy(checks, out / "bench" / "trade.csv")
    check_micro(checks)


# The accuracy columns every run of trade.csv must have, finite (bench/README.md):
# a residual or a gap that is NaN or missing would leave the run out of the
# fastest tables without a word.
TRADE_ACCURACY_COLUMNS = ("residual_rms", "relative_residual", "hard_violation_rms", "hard_stationarity_rms",
                          "relative_residual_hard", "objective_gap")


def check_trade_accuracy(checks, table):
    """CI: every run of the quick trade has the residuals and the objective gap, finite."""
    try:
        with open(table, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
    except OSError as error:
        checks.record(False, f"trade --quick: {table} unreadable: {error}")
        return
    missing = [c for c in TRADE_ACCURACY_COLUMNS if not rows or c not in rows[0]]
    bad = []
    for number, row in enumerate(rows, start=2):
        for column in TRADE_ACCURACY_COLUMNS:
            if column in missing:
                continue
            try:
                value = float(row[column])
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                bad.append(f"{table.name} line {number} ({row['scene']} {row['method']} K={row['iterations']}): "
                           f"{column} = {row[column]!r}")
    ok = bool(rows) and not missing and not bad
    summary = f"trade --quick: {len(rows)} runs, each with {', '.join(TRADE_ACCURACY_COLUMNS)} finite"
    if missing:
        summary += f" (missing: {', '.join(missing)})"
    if bad:
        summary += f" ({len(bad)} not finite)"
    checks.record(ok, summary, bad[:20])


def check_micro(checks):
    """CI: each Google Benchmark program runs every benchmark for about 1 ms
    and exits 0 (built and runnable; the numbers are not judged: timing lives
    in ./course bench --micro, never in a test)."""
    targets = micro_targets()
    if not targets:
        # ./course test needs Google Benchmark (requirements.py): a build
        # without its programs is a failure, never a check that went missing
        # (a fresh Debian 12 root, 2026-12-07: configured by ./course demo
        # before ./course test installed the library, the tree never saw it).
        checks.record(False, "Google Benchmark programs: none in this build (bench/bench_*.cpp are built where "
                      "the configure finds a Google Benchmark that links: see benchmark_DIR and "
                      f"CL_BENCHMARK_LINKS in {shown(BUILD / 'CMakeCache.txt')})")
        return
    with checks.timed("measurements: Google Benchmark programs, one short pass"):
        try:
            build_targets(targets)
        except (CourseError, BuildFailure) as error:
            checks.record(False, f"Google Benchmark programs: {error}")
            return
        for name in targets:
            done = subprocess.run([str(executable(name)), "--benchmark_min_time=0.001"], cwd=ROOT,
                                  capture_output=True, encoding="utf-8", errors="replace", check=False)
            runs = sum(1 for line in done.stdout.splitlines() if line.startswith("BM_"))
            ok = done.returncode == 0 and runs > 0
            checks.record(ok, f"{name}: {runs} benchmarks ran, about 1 ms each"
                          + ("" if ok else f" (exit {done.returncode})"),
                          [] if ok else (done.stdout + done.stderr).splitlines()[-20:])
