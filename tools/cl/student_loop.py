"""The student's loop, checked by ./course test in a temporary student release."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from . import grade
from .base import ROOT
from .labs import lab_dirs
from .release import write_release


def sub_course(tree, *args):
    """Run tree's own ./course (its tools/course.py) with its own build dir."""
    env = dict(os.environ, CL_BUILD_DIR=str(tree / "build"))
    done = subprocess.run([sys.executable, str(tree / "tools" / "course.py"), *args], cwd=tree, env=env,
                          capture_output=True, text=True, check=False)
    return done.returncode, (done.stdout + done.stderr).splitlines()


def lab_scores(results_json):
    """{labNN: [score, max]} from a results.json."""
    scores = {}
    try:
        data = json.loads(results_json.read_text())
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
    reference = spring.read_text()
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
    with tempfile.TemporaryDirectory(prefix="cl-release-") as work:
        tree = Path(work) / "release"
        write_release(lab3, tree)
        shipped = sorted(p.name for p in (tree / "solutions").iterdir())
        checks.record(shipped == [lab1, ids["lab02"]] and not (tree / "solutions" / lab3).exists(),
                      f"release lab03: solutions/ holds {', '.join(shipped)} only")

        # 1. A sign error in lab 01 costs lab 01 points, lab 03 (reference code) none.
        (tree / "labs" / lab1 / "single_spring.cpp").write_text(sign_error)
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
        pbd.write_text(pbd.read_text() + "\nint this_line_does_not_compile = ;\n")
        code, lines = sub_course(tree, "grade", "lab01", "lab04")
        scores = lab_scores(tree / "build" / "grade" / "results.json")
        text = "\n".join(lines)
        ok = (scores.get("lab01") == s1 and "BUILD lab04" in text and "pbd.cpp:" in text
              and "lab 04 links your lab 03 code: lab 03 scores" in text)
        checks.record(ok, "release lab03, lab 04 does not compile: lab 01 still grades "
                      f"({scores.get('lab01', [0, 0])[0]:g}/{s1[1]:g}), lab 04 shows the compiler's error",
                      [] if ok else lines)

        # 3. A crash in lab 01 is rerun under the sanitizers, which name the line.
        (tree / "labs" / lab1 / "single_spring.cpp").write_text(crash)
        line = next(i for i, l in enumerate(crash.splitlines(), 1) if "corrections.col(k) =" in l)
        where = f"labs/{lab1}/single_spring.cpp:{line}"
        code, lines = sub_course(tree, "grade", "lab01")
        text = "\n".join(lines)
        ok = "crashed (signal" in text and where in text
        checks.record(ok, f"release lab03, lab 01 writes past an unsized matrix: grade names {where}",
                      [] if ok else lines)
    checks.record(True, f"student loop checks: {time.monotonic() - start:.0f} s")
