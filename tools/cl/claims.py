"""./course claims: every number a handout quotes, reproduced by its command.

Each lab keeps its handout's numbers in labs/labNN_name/claims.json (the format:
docs/DESIGN.md §4, "Claims"): the quote as the page has it, the command beside
it, where the number is read (a CSV cell, a summary field, a printed line), the
value and the tolerance a correct solution reproduces it to. A claim whose
quote is no longer on the page fails too, so a number cannot outlive its text.
Commands run in a scratch folder (their relative --out lands there), each
once however many claims read it, with the student's code or, with
--solutions, the reference.
"""
import argparse
import csv
import json
import math
import re
import shlex
import subprocess
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .base import ROOT, CourseError
from .base import program as executable_path
from .build import BuildFailure, build_targets, configure
from .labs import lab_dirs, manifest, resolve_lab

FULL_TIMEOUT = 1800  # s, one command of the full run
QUICK_TIMEOUT = 120  # s, one command of --quick: a claim marked quick takes seconds
FIELDS = {"id", "quote", "command", "read", "value"}


def claims_path(lab):
    return ROOT / "labs" / lab / "claims.json"


def load_claims(lab):
    """The lab's claims, checked for shape; [] when it has none."""
    path = claims_path(lab)
    if not path.is_file():
        return []
    try:
        claims = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as error:
        raise CourseError(f"{path.relative_to(ROOT)}: not JSON ({error})", code=2) from None
    seen = set()
    for index, claim in enumerate(claims):
        where = f"{path.relative_to(ROOT)}: [{index}]"
        missing = FIELDS - set(claim)
        if missing:
            raise CourseError(f"{where}: missing {', '.join(sorted(missing))}", code=2)
        if claim["id"] in seen:
            raise CourseError(f"{where}: id '{claim['id']}' twice", code=2)
        seen.add(claim["id"])
    return claims


def squeeze(text):
    return re.sub(r"\s+", " ", text).strip()


def program_of(command, solutions):
    """(executable, args) of a claim's command: `./course run labNN ARGS` or
    `build/bin/NAME ARGS`; with `solutions`, a lab's reference."""
    words = shlex.split(command)
    if words[:2] == ["./course", "run"] and len(words) > 2:
        token, args = words[2], words[3:]
        lab = resolve_lab(token.removesuffix("_solution"))
        name = lab + ("_solution" if solutions or token.endswith("_solution") else "")
    elif words and words[0].startswith("build/bin/"):
        name, args = words[0][len("build/bin/"):], words[1:]
        match = re.fullmatch(r"(lab\d\d_[a-z0-9_]+?)(_solution)?", name)
        if match and solutions:
            name = match.group(1) + "_solution"
    else:
        raise CourseError(f"a claim's command must be ./course run or build/bin/: {command}", code=2)
    return name, args


def run_command(command, solutions, scratch, timeout, bin_dir=None):
    """(stdout + stderr, exit code, seconds) of one command, run in `scratch`
    with the programs of `bin_dir` (default build/bin)."""
    name, args = program_of(command, solutions)
    start = time.monotonic()
    try:
        done = subprocess.run([str(executable_path(name, bin_dir)), *args], cwd=scratch, capture_output=True,
                              encoding="utf-8", errors="replace",
                              timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return f"(ran past {timeout} s)", -1, time.monotonic() - start
    return done.stdout + done.stderr, done.returncode, time.monotonic() - start


def read_value(read, output, scratch):
    """The value a `read` spec points at (a number when it parses as one)."""
    if "stdout" in read:
        match = re.search(read["stdout"], output, re.MULTILINE)
        if not match:
            raise LookupError(f"no line matches /{read['stdout']}/")
        return as_number(match.group(1))
    if "csv" in read:
        with open(scratch / read["csv"], newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(handle))
        wanted = read.get("row", {})
        found = [row for row in rows if all(same(row.get(key), value) for key, value in wanted.items())]
        pick = read.get("pick", "one")
        if pick == "count":
            return len(found)
        if not found:
            raise LookupError(f"no row of {read['csv']} has {wanted}")
        column = read["column"]
        if column not in found[0]:
            raise LookupError(f"{read['csv']} has no column '{column}'")
        values = [as_number(row[column]) for row in found]
        if pick == "one":
            if len(found) != 1:
                raise LookupError(f"{len(found)} rows of {read['csv']} have {wanted}, not one")
            return values[0]
        return {"first": values[0], "last": values[-1], "max": max(values), "min": min(values)}[pick]
    for kind in ("summary", "json"):
        if kind in read:
            value = json.loads((scratch / read[kind]).read_text(encoding="utf-8"))
            for key in str(read["key"]).split("."):
                value = value[int(key)] if isinstance(value, list) else value[key]
            return as_number(value) if isinstance(value, str) else value
    raise LookupError(f"unknown read spec {read}")


def as_number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return text


def same(cell, wanted):
    if cell is None:
        return False
    a, b = as_number(cell), as_number(wanted)
    if isinstance(a, float) and isinstance(b, float):
        return a == b
    return str(cell) == str(wanted)


def holds(value, expected, tolerance):
    """True when `value` is `expected` within `tolerance` ({"abs": A} or {"rel": R}; exact when empty)."""
    if isinstance(expected, str) or isinstance(value, str) or value is None:
        return str(value) == str(expected)
    if isinstance(expected, bool) or isinstance(value, bool):
        return bool(value) == bool(expected)
    value, expected = float(value), float(expected)
    if math.isnan(value):
        return False
    if math.isinf(expected):
        return value == expected
    allowed = tolerance.get("abs", 0.0) + tolerance.get("rel", 0.0) * abs(expected)
    return abs(value - expected) <= allowed


def tolerance_text(tolerance):
    if not tolerance:
        return "exact"
    return ", ".join(f"{kind} {amount:g}" for kind, amount in tolerance.items())


def check_lab(lab, quick, solutions):
    """(held, total, failures) of one lab's claims: failures are lines to print."""
    claims = [c for c in load_claims(lab) if c.get("quick") or not quick]
    page = squeeze((ROOT / "labs" / lab / "README.md").read_text(encoding="utf-8"))
    failures = []
    commands = list(dict.fromkeys(c["command"] for c in claims))
    with tempfile.TemporaryDirectory(prefix="cl-claims-") as scratch:
        scratch = Path(scratch)
        timeout = QUICK_TIMEOUT if quick else FULL_TIMEOUT
        with ThreadPoolExecutor(max_workers=2) as pool:
            outputs = dict(zip(commands, pool.map(lambda c: run_command(c, solutions, scratch, timeout), commands)))
        for claim in claims:
            problem = None
            output, code, _ = outputs[claim["command"]]
            if squeeze(claim["quote"]) not in page:
                problem = f"the handout no longer says \"{claim['quote']}\""
            elif code != 0:
                lines = output.strip().splitlines() or ["(no output)"]
                problem = f"the command exits {code}: {lines[-1]}"
            else:
                try:
                    got = read_value(claim["read"], output, scratch)
                except (LookupError, OSError, ValueError, KeyError, IndexError) as error:
                    problem = f"cannot read the value: {error}"
                else:
                    if not holds(got, claim["value"], claim.get("tolerance", {})):
                        problem = (f"expected {claim['value']}, got {got} "
                                   f"(tolerance {tolerance_text(claim.get('tolerance', {}))})")
            if problem:
                failures.append(f"{claim['id']}: {problem}\n            {claim['command']}")
    return len(claims) - len(failures), len(claims), failures


def targets_for(labs, solutions):
    names = set()
    for lab in labs:
        for claim in load_claims(lab):
            names.add(program_of(claim["command"], solutions)[0])
    return sorted(names)


def run_claims(labs, quick, solutions, log=print):
    """{lab: (held, total, failures)} for the labs that have claims."""
    configure()
    wanted = targets_for(labs, solutions)
    if wanted:
        try:
            build_targets(wanted, log=None)
        except BuildFailure as failure:
            raise CourseError(str(failure), details=failure.lines) from None
    results = {}
    for lab in labs:
        if load_claims(lab):
            results[lab] = check_lab(lab, quick, solutions)
    return results


def cmd_claims(argv):
    parser = argparse.ArgumentParser(prog="course claims",
                                     description="reproduce every number a handout quotes (labs/*/claims.json)")
    parser.add_argument("labs", nargs="*", metavar="labNN", help="the labs (default: all that have claims)")
    parser.add_argument("--quick", action="store_true", help="only the claims whose commands take seconds")
    parser.add_argument("--solutions", action="store_true", help="with the reference code instead of yours")
    args = parser.parse_args(argv)
    labs = [resolve_lab(token) for token in args.labs] or lab_dirs()
    configure()
    if args.solutions:
        absent = [lab for lab in labs if not manifest().get(lab, {}).get("reference") and load_claims(lab)]
        if absent:
            raise CourseError(f"no reference here for {', '.join(absent)}: run without --solutions", code=2)
    failed = 0
    for lab, (held, total, failures) in run_claims(labs, args.quick, args.solutions).items():
        print(f"claims {lab}: {held}/{total} hold{' (quick)' if args.quick else ''}")
        for line in failures:
            print(f"  FAIL {line}")
        failed += bool(failures)
    return 1 if failed else 0
