"""The views in a real browser, a check of ./course test (docs/DESIGN.md §3,
"The trajectory"): ./course view's refusals and its comparison's file, then
pages of a short lab 04 run opened in headless Chromium (software WebGL) —
their body attributes against the files, the positions against
trajectory.bin, screenshots that are drawn and differ, and no control past
the window's edge at 800 and 1200 px.
"""
import json
import re
import shlex
import shutil
import subprocess
import sys

from .base import BIN, BUILD, ROOT
from .labs import manifest
from .requirements import browser as find_browser
from .view import decode_positions, load_run, write_view

CHROMIUM_FLAGS = ["--headless", "--disable-gpu", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                  "--enable-unsafe-swiftshader", "--enable-logging=stderr", "--v=0", "--virtual-time-budget=8000",
                  "--hide-scrollbars"]


def open_in_chromium(chromium, page, frame, screenshot, size=(800, 600)):
    """Load PAGE?frame=FRAME in headless Chromium in a window of `size` px;
    (body attributes, problems): the page's <body> data-* attributes and what
    went wrong (a console error, an uncaught exception, no DOM, a control past
    the window's edge)."""
    url = f"file://{page.resolve()}?frame={frame}"
    try:
        done = subprocess.run([chromium, *CHROMIUM_FLAGS, f"--window-size={size[0]},{size[1]}",
                               f"--screenshot={screenshot}", "--dump-dom", url],
                              capture_output=True, encoding="utf-8", errors="replace", timeout=60, check=False)
    except subprocess.TimeoutExpired:
        return {}, [f"{url}: Chromium ran past 60 s"]
    match = re.search(r"<body([^>]*)>", done.stdout)
    if not match:
        return {}, [f"{url}: no <body> in the DOM (exit {done.returncode}): {done.stderr.strip()[-300:]}"]
    attrs = {k: v.replace("&quot;", '"').replace("&amp;", "&")
             for k, v in re.findall(r'(data-[a-z-]+)="([^"]*)"', match.group(1))}
    problems = [f"{url}: console: {line.strip()[-200:]}" for line in done.stderr.splitlines()
                if "CONSOLE" in line and "Uncaught" in line]
    if "data-error" in attrs:
        problems.append(f"{url}: the page's error: {attrs['data-error']}")
    if attrs.get("data-ready") != "1":
        problems.append(f"{url}: data-ready is {attrs.get('data-ready')!r}, not 1 (no frame drawn)")
    if attrs.get("data-outside"):
        problems.append(f"{url} at {size[0]} x {size[1]} px: past or touching the window's edge: "
                        f"{attrs['data-outside']}")
    return attrs, problems


VIEW_BACKGROUND = (0xf4, 0xf4, 0xf0)  # the page's and the renderer's clear colour (view.py, view_player.js)


def screenshot_shares(first, second):
    """(share of non-background pixels of FIRST, of SECOND, share of pixels that
    differ), over the part of the 800 × 600 screenshots where the runs are drawn."""
    from PIL import Image, ImageChops

    # The drawing alone: below the heads-up lines, above the controls, left of the colour bar.
    images = [Image.open(path).convert("RGB") for path in (first, second)]
    images = [image.crop((0, 110, image.width - 180, image.height - 60)) for image in images]
    background = VIEW_BACKGROUND
    shares = []
    for image in images:
        flat = ImageChops.difference(image, Image.new("RGB", image.size, background)).convert("L")
        shares.append(sum(flat.point(lambda v: 255 if v > 12 else 0).histogram()[255:]) / (image.width * image.height))
    changed = ImageChops.difference(*images).convert("L").point(lambda v: 255 if v > 12 else 0)
    return shares[0], shares[1], changed.histogram()[255] / (images[0].width * images[0].height)


def drawn(share):
    """A screenshot's share of non-background pixels, as a drawn view has it:
    some mesh (>= 1 %), and the renderer's cleared background around it (a
    canvas never drawn is black: 100 %)."""
    return 0.01 <= share <= 0.95


def sample_problems(attrs, runs, frames, truth=None):
    """The page's decoded sample positions against trajectory.bin decoded here
    (to 1e-9 m), and, with `truth` (run -> final positions), against the run's
    own positions to the header's max_position_error."""
    problems = []
    try:
        samples = json.loads(attrs.get("data-sample", "[]"))
    except ValueError:
        return ["data-sample is not JSON"]
    if not samples:
        return ["no data-sample"]
    for r, particle, *shown in samples:
        header, data = runs[r]
        decoded = decode_positions(header, data, frames[r])[particle]
        gap = max(abs(a - b) for a, b in zip(shown, decoded))
        if gap > 1e-9:
            problems.append(f"run {r} particle {particle}: page {shown}, file {decoded} (|d| = {gap:.3g} m)")
        if truth and r in truth:
            error = max(abs(a - b) for a, b in zip(shown, truth[r][particle]))
            bound = header["max_position_error"] * (1 + 1e-6) + 1e-12
            if error > bound:
                problems.append(f"run {r} particle {particle}: {error:.3g} m from the run's position, "
                                f"over the stated {header['max_position_error']:.3g} m")
    return problems


def view_refusal_problems(scratch):
    """./course view on a folder without a trajectory, a truncated trajectory.bin
    and a corrupt header: exit 2, one line, nothing written."""
    problems = []
    good = scratch / "a"
    cases = {"empty": "no trajectory.json", "truncated": "truncated", "corrupt": "not a trajectory"}
    for name, expected in cases.items():
        folder = scratch / name
        folder.mkdir()
        if name == "truncated":
            shutil.copy(good / "trajectory.json", folder)
            (folder / "trajectory.bin").write_bytes((good / "trajectory.bin").read_bytes()[:-5])
        if name == "corrupt":
            cut = (good / "trajectory.json").read_text(encoding="utf-8")[:200]
            (folder / "trajectory.json").write_text(cut, encoding="utf-8")
            shutil.copy(good / "trajectory.bin", folder)
        before = sorted(folder.iterdir())
        done = subprocess.run([sys.executable, str(ROOT / "tools" / "course.py"), "view", str(folder)],
                              capture_output=True, encoding="utf-8", errors="replace", check=False)
        lines = done.stderr.splitlines()
        if done.returncode != 2 or len(lines) != 1 or expected not in lines[0]:
            problems.append(f"view {name}: exit {done.returncode}, stderr {lines[:3]} (expected 2, one line "
                            f"saying '{expected}')")
        if sorted(folder.iterdir()) != before:
            problems.append(f"view {name}: wrote something on a refusal")
    return problems


def comparison_problems(scratch):
    """./course view A B without --output: the page goes to view-A-vs-B.html
    beside A, the path is printed, and A's own view.html is left alone."""
    own = scratch / "a" / "view.html"
    own.write_text("a's own view", encoding="utf-8")
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "course.py"), "view", str(scratch / "a"),
                           str(scratch / "b")], capture_output=True, encoding="utf-8", errors="replace", check=False)
    expected = scratch / "view-a-vs-b.html"
    problems = []
    if done.returncode != 0 or not expected.is_file() or expected.name not in done.stdout:
        problems.append(f"view a b: exit {done.returncode}, {expected.name} "
                        f"{'written' if expected.is_file() else 'not written'}, stdout {done.stdout.strip()[:200]!r}")
    if own.read_text(encoding="utf-8") != "a's own view":
        problems.append("view a b overwrote a/view.html")
    own.unlink()
    expected.unlink(missing_ok=True)
    return problems


def check_browser(checks):
    """./course view's refusals, then the view in a real browser (headless
    Chromium, software WebGL): a short lab 04 run, a two-run comparison and two
    runs of different particle counts."""
    program = BIN / "lab04_pbd_solution"
    scratch = BUILD / "test-view"
    shutil.rmtree(scratch, ignore_errors=True)
    scratch.mkdir(parents=True)
    # The other run of a different particle count: lab 14's drape, whose colliders
    # the page must draw, where its reference is here; in a student release
    # before lab 14's week, a rope of lab 04.
    drape = manifest().get("lab14_contact", {}).get("reference", False)
    other = "drape" if drape else "rope"
    runs = {"a": ["--scene", "curtain-8", "--iterations", "1", "--steps", "60", "--frames", "4"],
            "b": ["--scene", "curtain-8", "--iterations", "16", "--steps", "60", "--frames", "4"],
            other: (["--scene", "drape-sphere", "--steps", "2", "--frames", "1"] if drape
                    else ["--scene", "rope-50", "--steps", "40", "--frames", "5"])}
    for name, args in runs.items():
        runner = BIN / "lab14_contact_solution" if name == "drape" else program
        done = subprocess.run([str(runner), *args, "--out", str(scratch / name),
                               "--summary", str(scratch / f"{name}.json")],
                              capture_output=True, encoding="utf-8", errors="replace", check=False)
        if done.returncode != 0:
            checks.record(False, f"the view's runs: {runner.name} {shlex.join(args)} exited {done.returncode}",
                          done.stderr.splitlines()[-3:])
            return
    problems = view_refusal_problems(scratch)
    checks.record(not problems, "./course view refuses a folder without a trajectory, a truncated and a corrupt "
                  "one (exit 2, one line, nothing written)", problems)
    problems = comparison_problems(scratch)
    checks.record(not problems, "./course view a b writes view-a-vs-b.html beside a and says so; a/view.html "
                  "is left alone", problems)
    chromium = find_browser()
    if not chromium:
        print("skip  the view in a browser: no chromium, chromium-browser or google-chrome on PATH (./course test "
              "installs Debian's chromium when run as root)")
        return

    run_a = load_run(scratch / "a")
    last = run_a[0]["frame_count"] - 1
    final = json.loads((scratch / "a.json").read_text(encoding="utf-8"))["positions"]
    single = write_view([scratch / "a"])
    problems, shots = [], []
    for frame in (0, last):
        shot = scratch / f"a-{frame}.png"
        attrs, found = open_in_chromium(chromium, single, frame, shot)
        problems += found
        expected = {"data-frames": str(run_a[0]["frame_count"]), "data-particles": str(run_a[0]["particles"]),
                    "data-springs": str(len(run_a[0]["springs"]) // 2), "data-frame": str(frame)}
        problems += [f"frame {frame}: {k} = {attrs.get(k)!r}, the file says {v}" for k, v in expected.items()
                     if attrs.get(k) != v]
        if attrs:
            problems += sample_problems(attrs, [run_a], [frame], {0: final} if frame == last else None)
        shots.append(shot)
    if all(shot.is_file() for shot in shots):
        first, second, changed = screenshot_shares(*shots)
        if not all(drawn(share) for share in (first, second)):
            problems.append(f"a screenshot is blank: {100 * first:.2f} % and {100 * second:.2f} % of its pixels "
                            "are not background (a drawn view has some, and a cleared background around them)")
        if changed < 0.001:
            problems.append(f"the first and the last frame look the same ({100 * changed:.3f} % of pixels differ)")
    else:
        problems.append("no screenshot written")
    checks.record(not problems, f"view of a lab 04 run in headless Chromium: {last + 1} frames, positions as in "
                  "trajectory.bin and within the stated error of the run's, no console error, first and last "
                  "frame drawn and different", problems)

    problems = []
    run_b = load_run(scratch / "b")
    run_other = load_run(scratch / other)
    if "colliders" in run_a[0] or (drape and len(run_other[0].get("colliders", [])) != 2):
        problems.append(f"colliders in trajectory.json: lab 04's {run_a[0].get('colliders')} (none expected), "
                        f"drape-sphere's {run_other[0].get('colliders')} (its scene has 2)")
    for names, runs_shown in ((["a", "b"], [run_a, run_b]), (["a", other], [run_a, run_other])):
        page = write_view([scratch / n for n in names], scratch / f"view-{'-'.join(names)}.html")
        shot = scratch / f"{'-'.join(names)}.png"
        attrs, found = open_in_chromium(chromium, page, last, shot)
        problems += found
        expected = {"data-runs": "2",
                    "data-particles": ",".join(str(r[0]["particles"]) for r in runs_shown),
                    "data-frames": ",".join(str(r[0]["frame_count"]) for r in runs_shown),
                    "data-colliders": ",".join(str(len(r[0].get("colliders", []))) for r in runs_shown)}
        problems += [f"{'+'.join(names)}: {k} = {attrs.get(k)!r}, the files say {v}" for k, v in expected.items()
                     if attrs.get(k) != v]
        if attrs and names[1] == "b":
            problems += sample_problems(attrs, runs_shown, [last, last])
            problems += open_in_chromium(chromium, page, last, scratch / "wide.png", (1200, 800))[1]
        if shot.is_file():
            share = screenshot_shares(shot, shot)[0]
            if not drawn(share):
                problems.append(f"{'+'.join(names)}: the screenshot is blank ({100 * share:.2f} %)")
    checks.record(not problems, "side-by-side views in headless Chromium: K = 1 against K = 16 (one clock, and "
                  "every control inside the window at 800 and 1200 px), "
                  + ("a curtain beside lab 14's drape (different particle counts; the drape's sphere and floor "
                     "drawn, no collider in lab 04's)" if drape else
                     "a curtain beside a rope (different particle counts)"), problems)
