"""./course autograder labNN: the Gradescope autograder bundle for one lab, and
the CI check that builds one and grades four submissions with it.

The bundle is a zip with, at its top (Gradescope unpacks it into /autograder/source):
  setup.sh          run once as root: installs what ./course grade needs (apt) and
                    builds the lab's graded tests against the stubs (tools/gradescope/)
  run_autograder    run per submission: the student's files in, rebuild, grade,
                    /autograder/results/results.json (always valid JSON)
  autograder_run.py what both of them call
  autograder.json   the lab and the time limits
  course/           the student release of the lab's week (write_release:
                    stubs for every lab, the reference code of earlier labs) plus
                    the lab's hidden tests, tests/labNN_x/hidden_*.cpp
A TEST_CASE tagged [hidden] lives in a tests/*/hidden_*.cpp file: the student
release leaves those files out, the bundle runs them and shows them to the student
after the grades are published (visibility "after_published").
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

from . import grade
from .base import BUILD, ROOT, CourseError, check_tree, show
from .labs import lab_dirs, resolve_lab
from .release import write_release
TEMPLATES = ROOT / "tools" / "gradescope"
TEMPLATE_FILES = ("setup.sh", "run_autograder", "autograder_run.py")
HIDDEN_TEST = re.compile(r"^tests/([^/]+)/hidden_[^/]*\.cpp$")
CASE_TIMEOUT = 30  # seconds per test case in the bundle (the local grader allows 120)
# Seconds for the whole submission: the cases left at the end score 0 with a
# message. Below Gradescope's default autograder timeout (10 minutes), so that
# results.json is written before Gradescope stops the container.
RUN_LIMIT = 480


def is_hidden_test(path):
    """True for tests/labNN_x/hidden_*.cpp (a course-relative path): cases only the bundle runs."""
    return HIDDEN_TEST.match(str(path)) is not None


def bundle_keep(lab):
    """write_release's `keep` for the bundle of `lab`: its own hidden tests, no other lab's."""
    def keep(path):
        match = HIDDEN_TEST.match(path)
        return match is None or match.group(1) == lab
    return keep


def points_in_sources(lab):
    """(visible points, hidden points, hidden cases) of the lab's graded TEST_CASEs,
    read from tests/LAB/*.cpp: known before anything is built."""
    tag, visible, hidden, count = grade.lab_tag(lab).lower(), 0.0, 0.0, 0
    for source in sorted((ROOT / "tests" / lab).glob("*.cpp")):
        text = source.read_text(encoding="utf-8")
        for tags in re.findall(r'TEST_CASE\s*\(\s*"(?:[^"\\]|\\.)*"\s*,\s*"([^"]*)"', text):
            if tag not in tags.lower():
                continue
            points = sum(float(p) for p in grade.PTS_TAG.findall(tags) if re.fullmatch(r"[0-9.]+", p))
            if "[hidden]" in tags.lower():
                hidden, count = hidden + points, count + 1
            else:
                visible += points
    return visible, hidden, count


def write_bundle(lab, zip_path, case_timeout=CASE_TIMEOUT, run_limit=RUN_LIMIT):
    """Write the bundle for `lab` to zip_path; return (file count, the student's file names)."""
    students = sorted(p.name for p in (ROOT / "solutions" / lab).glob("*.cpp"))
    if not students:
        raise CourseError(f"no reference in solutions/{lab}/: the bundle cannot be tested", code=2)
    with tempfile.TemporaryDirectory(prefix="cl-bundle-") as work:
        stage = Path(work)
        count = write_release(lab, stage / "course", keep=bundle_keep(lab))
        for name in TEMPLATE_FILES:
            shutil.copy2(TEMPLATES / name, stage / name)
        config = {"lab": lab, "files": students, "case_timeout": case_timeout, "run_limit": run_limit}
        (stage / "autograder.json").write_text(json.dumps(config, indent=2) + "\n", encoding="utf-8")
        zip_path.parent.mkdir(parents=True, exist_ok=True)
        partial = zip_path.with_name(zip_path.name + ".partial")
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as bundle:
            for path in sorted(stage.rglob("*")):
                if path.is_file():
                    bundle.write(path, path.relative_to(stage).as_posix())  # keeps the mode bits
        partial.replace(zip_path)
    return count + len(TEMPLATE_FILES) + 1, students


def cmd_autograder(argv):
    parser = argparse.ArgumentParser(prog="course autograder",
                                     description="Write the Gradescope autograder bundle for one lab.")
    parser.add_argument("lab", metavar="labNN")
    parser.add_argument("--out", metavar="FILE.zip", help="where to write it (default build/gradescope/labNN.zip)")
    parser.add_argument("--case-timeout", type=float, default=CASE_TIMEOUT, metavar="S",
                        help=f"time limit of one test case, s (default {CASE_TIMEOUT})")
    parser.add_argument("--run-limit", type=float, default=RUN_LIMIT, metavar="S",
                        help=f"time limit of one submission's whole run, s (default {RUN_LIMIT}; "
                             "keep it below Gradescope's autograder timeout)")
    args = parser.parse_args(argv)
    lab = resolve_lab(args.lab)
    tag = grade.lab_id(lab)
    out = Path(args.out).resolve() if args.out else BUILD / "gradescope" / f"{tag}.zip"
    count, students = write_bundle(lab, out, args.case_timeout, args.run_limit)
    visible, hidden, hidden_count = points_in_sources(lab)
    fmt = grade.fmt_points
    print(f"{show(out)}: the Gradescope autograder for {tag} ({count} files)")
    print(f"  accepts {', '.join(students)} (anywhere in the submission)")
    print(f"  {fmt(visible + hidden)} points: {fmt(visible)} in the tests students have, {fmt(hidden)} in "
          f"{hidden_count} hidden case{'s' if hidden_count != 1 else ''} (shown after the grades are published)")
    print(f"  limits: {args.case_timeout:g} s per test case, {args.run_limit:g} s per submission")
    print("  upload it as the assignment's autograder (Configure Autograder > Zip file upload; "
          "base image Ubuntu 22.04)")
    return 0


# ---------------------------------------------------------------- CI check

def unpack(zip_path, dest):
    """Unzip like Gradescope does, keeping the executable bits."""
    with zipfile.ZipFile(zip_path) as bundle:
        for info in bundle.infolist():
            bundle.extract(info, dest)
            mode = (info.external_attr >> 16) & 0o777
            if mode:
                os.chmod(dest / info.filename, mode)


def results_of(path):
    """(results.json as a dict, or None, and the problem)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        return None, f"results.json is not valid JSON: {error}"
    if not isinstance(data.get("tests"), list) or "score" not in data:
        return None, "results.json has no score or no tests list"
    return data, ""


def check_autograder(checks, lab_token="lab02"):
    """Issue 14's promise, tested for real: the bundle of lab 02 unpacked into a
    folder laid out like Gradescope's, setup.sh, then run_autograder on (a) the
    reference, (b) the stubs, (c) code that does not compile, (d) an endless loop,
    (e) an empty submission."""
    ids = {grade.lab_id(lab): lab for lab in lab_dirs()}
    lab = ids.get(lab_token)
    if lab is None:
        return
    reference = (ROOT / "solutions" / lab / "gauss_seidel.cpp").read_text(encoding="utf-8")
    stub = (ROOT / "labs" / lab / "gauss_seidel.cpp").read_text(encoding="utf-8")
    signature = "const std::vector<Spring>& springs, const std::vector<int>& order) {\n"
    endless = reference.replace(signature, signature + "  for (volatile long spin = 0;; spin = spin + 1) {\n  }\n", 1)
    if endless == reference:
        checks.record(False, "autograder: cannot plant an endless loop in solutions/lab02 (code changed?)")
        return
    broken = reference + "\nint this_line_does_not_compile = ;\n"
    start = time.monotonic()
    with check_tree() as root:  # the student loop's tree was here too (check_tree)
        source = root / "source"
        zip_path = root / f"{lab_token}.zip"
        write_bundle(lab, zip_path)
        unpack(zip_path, source)
        tree = source / "course"
        shipped = sorted(p.name for p in (tree / "solutions").iterdir())
        hidden = sorted(str(p.relative_to(tree)) for p in tree.glob("tests/*/hidden_*.cpp"))
        ok = (shipped == [ids["lab01"]] and hidden and all(f"tests/{lab}/" in h for h in hidden)
              and all(os.access(source / name, os.X_OK) for name in ("setup.sh", "run_autograder")))
        checks.record(ok, f"autograder {lab_token}: bundle holds solutions/{', '.join(shipped)} and "
                      f"{len(hidden)} hidden test file(s) of {lab_token} only",
                      [] if ok else [f"solutions: {shipped}", f"hidden: {hidden}"])
        if not ok:
            return

        env = dict(os.environ, AUTOGRADER_ROOT=str(root), AUTOGRADER_PREBUILD_ASAN="0")
        env.pop("CL_BUILD_DIR", None)
        began = time.monotonic()
        done = subprocess.run(["bash", str(source / "setup.sh")], cwd=source, env=env, capture_output=True,
                              encoding="utf-8", errors="replace", check=False)
        lines = (done.stdout + done.stderr).splitlines()
        checks.record(done.returncode == 0, f"autograder {lab_token}: setup.sh "
                      f"({time.monotonic() - began:.0f} s): {lines[-1] if lines else 'no output'}",
                      [] if done.returncode == 0 else lines[-20:])
        if done.returncode != 0:
            return
        shutil.copy2(source / "run_autograder", root / "run_autograder")  # where Gradescope puts it

        def submit(files, **limits):
            submission = root / "submission"
            shutil.rmtree(submission, ignore_errors=True)
            submission.mkdir(parents=True)
            for name, text in files.items():
                (submission / name).parent.mkdir(parents=True, exist_ok=True)
                (submission / name).write_text(text, encoding="utf-8")
            results = root / "results" / "results.json"
            results.unlink(missing_ok=True)
            began = time.monotonic()
            run_env = dict(env, **{f"AUTOGRADER_{k.upper()}": str(v) for k, v in limits.items()})
            done = subprocess.run([str(root / "run_autograder")], cwd=root, env=run_env, capture_output=True,
                                  encoding="utf-8", errors="replace", check=False)
            data, problem = results_of(results)
            took = time.monotonic() - began
            if data is None:
                return None, [problem, *(done.stdout + done.stderr).splitlines()[-10:]], took
            max_score = sum(t["max_score"] for t in data["tests"])
            return data, [f"score {grade.fmt_points(data['score'])}/{grade.fmt_points(max_score)}"], took

        def output_lines(data):
            return [f"output: {line}" for line in data["output"].splitlines()[:6]]

        # (a) the reference, with an extra file: full marks, hidden cases after publishing.
        data, said, took = submit({"gauss_seidel.cpp": reference, "notes.txt": "my notes\n"})
        ok = data is not None and data["score"] == sum(t["max_score"] for t in data["tests"]) > 0
        hidden_entries = [t for t in data["tests"] if t["visibility"] == "after_published"] if data else []
        ok = ok and bool(hidden_entries) and "notes.txt" in data["output"]
        checks.record(ok, f"autograder {lab_token} (a) the reference: {said[0]}, "
                      f"{len(hidden_entries)} hidden case(s) after_published, notes.txt listed ({took:.0f} s)",
                      [] if ok else said + (output_lines(data) if data else []))

        # (b) the stubs: 0, every case ran and says not implemented.
        data, said, took = submit({"gauss_seidel.cpp": stub})
        graded = [t for t in data["tests"] if t["max_score"] > 0] if data else []
        ok = data is not None and data["score"] == 0 and graded and all(
            "not implemented" in t["output"].lower() for t in graded)
        checks.record(ok, f"autograder {lab_token} (b) the stubs: {said[0]} ({took:.0f} s)",
                      [] if ok else said + [f"{t['name']}: {t['output'][:120]}" for t in graded])

        # (c) does not compile: 0 and the compiler's error naming the file.
        data, said, took = submit({"gauss_seidel.cpp": broken})
        ok = (data is not None and data["score"] == 0 and f"labs/{lab}/gauss_seidel.cpp:" in data["output"]
              and "error" in data["output"])
        checks.record(ok, f"autograder {lab_token} (c) does not compile: {said[0]}, "
                      f"the compiler's error in output ({took:.0f} s)", output_lines(data) if data else said)

        # (d) an endless loop: the time limit fires, results.json is valid. The
        # submission's limit leaves room for its rebuild, which (c) just timed: on
        # a busy machine a fixed 10 s was spent compiling before any case ran.
        data, said, took = submit({"gauss_seidel.cpp": endless}, case_timeout=3, run_limit=round(10 + took))
        timed_out = [t["name"] for t in data["tests"] if "timed out" in t["output"]] if data else []
        ok = data is not None and data["score"] == 0 and bool(timed_out)
        checks.record(ok, f"autograder {lab_token} (d) an endless loop: {said[0]}, {len(timed_out)} case(s) "
                      f"timed out, results.json valid ({took:.0f} s)",
                      [f"first: {timed_out[0]}" if timed_out else "no case timed out", *(output_lines(data) if data else said)])

        # (e) nothing submitted: 0 and a message naming the missing file.
        data, said, took = submit({})
        ok = data is not None and data["score"] == 0 and "gauss_seidel.cpp is missing" in data["output"]
        checks.record(ok, f"autograder {lab_token} (e) gauss_seidel.cpp missing: {said[0]}, named in output "
                      f"({took:.0f} s)", [] if ok else said + (output_lines(data) if data else []))
    checks.record(True, f"autograder checks: {time.monotonic() - start:.0f} s")

