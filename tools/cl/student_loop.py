"""The student's loop, checked by ./course test in a temporary student release."""
import json
import os
import re
import shutil
import subprocess
import sys
import time

from . import grade
from .base import ROOT, check_tree
from .labs import lab_dirs
from .release import advance_release, write_release


def sub_course(tree, *args):
    """Run tree's own ./course (its tools/course.py) with its own build dir."""
    env = dict(os.environ, CL_BUILD_DIR=str(tree / "build"))
    done = subprocess.run([sys.executable, str(tree / "tools" / "course.py"), *args], cwd=tree, env=env,
                          capture_output=True, encoding="utf-8", errors="replace", check=False)
    return done.returncode, (done.stdout + done.stderr).splitlines()


def lab_scores(results_json):
    """{labNN: [score, max]} from a results.json."""
    scores = {}
    try:
        data = json.loads(results_json.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return scores
    for test in data["tests"]:
        tag = test["name"].split(":", 1)[0]
        entry = scores.setdefault(tag, [0, 0])
        entry[0] += test["score"]
        entry[1] += test["max_score"]
    return scores


def check_student_loop(checks):
    """Issue 13's promises, proved in a student release of lab 03 (one temp tree,
    one build): a wrong lab 01 is charged in lab 01 only; a lab that does not
    compile blocks no other; a crash is located by the sanitizer build."""
    ids = {grade.lab_id(lab): lab for lab in lab_dirs()}
    if not all(k in ids for k in ("lab01", "lab03", "lab04")):
        return
    lab1, lab3, lab4 = ids["lab01"], ids["lab03"], ids["lab04"]
    spring = ROOT / "solutions" / lab1 / "single_spring.cpp"
    reference = spring.read_text(encoding="utf-8")
    sign_error = reference.replace("correction.dx_i = -(", "correction.dx_i = (")
    bug = "  return (-constraint / denominator) * (gradients * inv_mass.asDiagonal());\n"
    crash = reference.replace(bug, "  Eigen::Matrix3Xd corrections;  // never sized: the bug\n"
                              "  for (Eigen::Index k = 0; k < gradients.cols(); ++k)\n"
                              "    corrections.col(k) = (-constraint * inv_mass[k] / denominator) * gradients.col(k);\n"
                              "  return corrections;\n")
    if sign_error == reference or crash == reference:
        checks.record(False, "student loop: cannot plant the bugs in solutions/lab01 (code changed?)")
        return
    start = time.monotonic()
    with check_tree() as work:
        tree = work / "source" / "course"  # where the autograder check's tree will be (check_tree)
        write_release(lab3, tree)
        shipped = sorted(p.name for p in (tree / "solutions").iterdir())
        checks.record(shipped == [lab1, ids["lab02"]] and not (tree / "solutions" / lab3).exists(),
                      f"release lab03: solutions/ holds {', '.join(shipped)} only")

        # 1. A sign error in lab 01 costs lab 01 points, lab 03 (reference code) none.
        (tree / "labs" / lab1 / "single_spring.cpp").write_text(sign_error, encoding="utf-8")
        for source in (ROOT / "solutions" / lab3).glob("*.cpp"):
            shutil.copy2(source, tree / "labs" / lab3 / source.name)
        code, lines = sub_course(tree, "grade", "lab01", "lab03")
        scores = lab_scores(tree / "build" / "grade" / "results.json")
        s1, s3 = scores.get("lab01", [0, 0]), scores.get("lab03", [0, 1])
        checks.record(s3[1] > 0 and s3[0] == s3[1] and s1[0] < s1[1],
                      f"release lab03, lab 01 with a sign error: lab01 {s1[0]:g}/{s1[1]:g}, "
                      f"lab03 {s3[0]:g}/{s3[1]:g} (full: charged once)", [] if s3[0] == s3[1] else lines)

        # 2. Lab 04 does not compile: lab 01 still grades, lab 04 shows the error.
        pbd = tree / "labs" / lab4 / "pbd.cpp"
        pbd.write_text(pbd.read_text(encoding="utf-8") + "\nint this_line_does_not_compile = ;\n", encoding="utf-8")
        code, lines = sub_course(tree, "grade", "lab01", "lab04")
        scores = lab_scores(tree / "build" / "grade" / "results.json")
        text = "\n".join(lines)
        ok = (scores.get("lab01") == s1 and "BUILD lab04" in text and "pbd.cpp:" in text
              and "lab 04 links your lab 03 code: lab 03 scores" in text)
        checks.record(ok, "release lab03, lab 04 does not compile: lab 01 still grades "
                      f"({scores.get('lab01', [0, 0])[0]:g}/{s1[1]:g}), lab 04 shows the compiler's error",
                      [] if ok else lines)

        # 3. A crash in lab 01 is rerun under the sanitizers, which name the line.
        (tree / "labs" / lab1 / "single_spring.cpp").write_text(crash, encoding="utf-8")
        line = next(i for i, l in enumerate(crash.splitlines(), 1) if "corrections.col(k) =" in l)
        where = f"labs/{lab1}/single_spring.cpp:{line}"
        code, lines = sub_course(tree, "grade", "lab01")
        text = "\n".join(lines)
        ok = "crashed (signal" in text and where in text
        checks.record(ok, f"release lab03, lab 01 writes past an unsized matrix: grade names {where}",
                      [] if ok else lines)

        # 4. ./course demo in the week's release: the labs with a reference run,
        # the others are named in one line as skipped (never a stub's exit 3).
        check_release_demo(checks, tree, lab3)

        # The same tree and build, a later week: its executables and hints.
        for lab in (lab1, lab3, lab4):
            for source in (ROOT / "solutions" / lab).glob("*.cpp"):
                shutil.copy2(ROOT / "labs" / lab / source.name, tree / "labs" / lab / source.name)
        if "lab08" in ids:
            check_later_week(checks, tree, ids)
    checks.record(True, f"student loop checks: {time.monotonic() - start:.0f} s")


# Short runs of the student's executables in lab 08's week, with the labs they
# use from earlier weeks shipped as references: they must run (issue 19: an
# executable links the reference of every earlier lab that has one). Labs 07
# and 10 are taken as written (their reference copied into labs/); lab 08 is
# still its stubs, which --method pbd does not call.
LATER_WEEK_RUNS = [
    ("lab10", ["--scene", "flat-curtain-32", "--levels", "2", "--steps", "2"]),
    ("lab08", ["--scene", "hanging-spring", "--method", "pbd", "--iterations", "1", "--steps", "2"]),
    ("lab07", ["--scene", "ragdoll-chain-20", "--compare-pbd", "1", "--compare-substeps", "1", "--steps", "2"]),
]
WRITTEN = ("lab07", "lab10")  # labs whose student files are the reference in that check
TARGET = re.compile(r"\b(lab\d\d)(?:_[a-z0-9_]*?)?_solution\b")


def check_later_week(checks, tree, ids, week="lab08"):
    """The lab 03 release advanced to lab 08's week (references of labs 01-07,
    stubs from 08 on): it equals a fresh release; the student's executables
    that use earlier labs run; no printed hint names a reference that is not
    there."""
    lab = ids[week]
    differ = advance_release(tree, lab)
    checks.record(not differ, f"release lab03 advanced to {week}: the same files as ./course release {week}",
                  differ[:10])
    present = {grade.lab_id(p.name) for p in (tree / "solutions").iterdir()}
    for written in (ids[tag] for tag in WRITTEN if tag in ids):
        for source in (ROOT / "solutions" / written).glob("*.cpp"):
            shutil.copy(source, tree / "labs" / written / source.name)  # a new mtime: make rebuilds it
    said = []
    for program, args in LATER_WEEK_RUNS:
        if grade.lab_id(program) not in ids:
            continue
        out = tree / "out" / f"later-week-{program}"
        code, lines = sub_course(tree, "run", program, *args, "--out", str(out))
        said += lines
        checks.record(code == 0, f"release {week}: ./course run {program} {' '.join(args)}: exit code {code}",
                      [] if code == 0 else lines[-8:])
    empty = tree / "out" / "nothing-yet"
    empty.mkdir(parents=True, exist_ok=True)
    for command in (["plots", "-v", str(empty)], ["help"], ["run"]):
        said += sub_course(tree, *command)[1]
    missing = sorted({line.strip() for line in said for m in TARGET.finditer(line) if m[1] not in present})
    checks.record(not missing, f"release {week}: no printed hint names a reference that is not shipped "
                  f"(./course plots -v, help, run)", missing[:10])


def check_release_demo(checks, tree, week):
    """./course demo in TREE, the release of `week`: exit 0, the labs with a
    reference shipped ran (their folders in out/), and one line names the
    skipped ones, the week's lab first."""
    code, lines = sub_course(tree, "demo")
    shipped = sorted(p.name for p in (tree / "solutions").iterdir() if p.is_dir())
    ran = [lab for lab in shipped if (tree / "out" / lab).is_dir()]
    said = [line for line in lines if "demo skipped for" in line]
    ok = (code == 0 and ran == shipped and len(said) == 1
          and said[0].strip().startswith(f"demo skipped for {grade.lab_id(week)},"))
    checks.record(ok, f"release {grade.lab_id(week)}: ./course demo exits {code}, runs "
                  f"{', '.join(grade.lab_id(lab) for lab in ran) or 'nothing'}, "
                  f"and names the skipped labs in one line", [] if ok else lines[-12:])
