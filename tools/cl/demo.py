"""./course demo and ./course run: the labs' executables; the demo's views
(./course view of every run that kept a trajectory, and demo.txt's `view:`
comparisons) and out/index.html, the page that links them all."""
import argparse
import html
import json
import os
import shlex
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

from . import grade
from .base import ROOT, CourseError, become, show, under_root
from .build import BuildFailure, build_targets, configure
from .labs import demo_lines, executable, lab_dirs, manifest, resolve_lab, view_lines
from .plots import plots_failed, run_plots
from .view import comparison_name, write_view


def run_demos(out, echo=True, labs=None, quick=False):
    """Run the demo lines of `labs` (default: every lab) into OUT/<lab> with the
    reference executable. A lab without a reference here (in a student release:
    the week's lab and the later ones) is skipped, all of them named in one
    line: a stub would only exit 3. `quick`: demo.txt's `# quick:` lengths
    (labs.demo_lines). Raise on the first failure."""
    configure()
    entries = manifest()
    labs = [lab for lab in (labs or lab_dirs()) if demo_lines(lab) and lab in entries]
    if not labs:
        print("no lab has a demo.txt yet")
    skipped = [lab for lab in labs if not entries[lab]["reference"]]
    if skipped:
        print(f"  demo skipped for {', '.join(grade.lab_id(lab) for lab in skipped)}: no reference in this tree "
              f"yet (solutions/ gets it after the deadline); run your own with ./course run "
              f"{grade.lab_id(skipped[0])} ...", flush=True)
    for lab in labs:
        if lab in skipped:
            continue
        name = lab + "_solution"
        try:
            build_targets([name], log=None)
        except BuildFailure as failure:
            raise CourseError(f"{name} does not build", details=failure.lines) from None
        program = executable(name)
        lab_out = out / lab
        lab_out.mkdir(parents=True, exist_ok=True)
        for args in demo_lines(lab, quick):
            shown = shlex.join([program.name, *(a.replace("{out}", show(lab_out)) for a in args)])
            if echo:
                print("  " + shown, flush=True)
            argv = [str(program), *(arg.replace("{out}", str(lab_out)) for arg in args)]
            done = subprocess.run(argv, cwd=ROOT, capture_output=True, encoding="utf-8", errors="replace", check=False)
            if done.returncode != 0:
                raise CourseError(f"{shown} exited with code {done.returncode}",
                                  details=done.stderr.splitlines())


def write_views(out, labs=None, echo=True):
    """The views of OUT/<lab>: DIR/view.html for every DIR with a trajectory,
    and OUT/<lab>/view-A-vs-B.html for each `view: {out}/A {out}/B` line of the
    lab's demo.txt. Returns the paths written; raises (CourseError) on a refusal."""
    written = []
    for lab in labs or lab_dirs():
        lab_out = out / lab
        if not lab_out.is_dir():
            continue
        for header in sorted(lab_out.rglob("trajectory.json")):
            written.append(write_view([header.parent]))
        for dirs in view_lines(lab):
            folders = [Path(d.replace("{out}", str(lab_out))) for d in dirs]
            written.append(write_view(folders, lab_out / comparison_name(*folders)))
    if echo:
        for path in written:
            print(f"  view: {show(path)}")
    return written


def _href(path, out):
    """A link from out/index.html to `path`."""
    return html.escape(os.path.relpath(path, out).replace(os.sep, "/"), quote=True)


def index_page(out):
    """out/index.html's text: per lab, its views, its figures (thumbnails) and its handout."""
    sections = []
    for lab in lab_dirs():
        lab_out = out / lab
        if not lab_out.is_dir():
            continue
        figures = sorted(p for p in lab_out.rglob("*") if p.suffix in (".png", ".gif"))
        views = sorted(p for p in lab_out.rglob("*.html") if p.name == "view.html" or p.name.startswith("view-"))
        if not figures and not views:
            continue
        items = "".join(f'<li><a href="{_href(v, out)}">{html.escape(v.relative_to(lab_out).as_posix())}</a></li>'
                        for v in views)
        thumbs = "".join(f'<a href="{_href(f, out)}" title="{_href(f, out)}"><img src="{_href(f, out)}" '
                         f'alt="{_href(f, out)}" loading="lazy"></a>' for f in figures)
        readme = ROOT / "labs" / lab / "README.md"
        handout = f' · <a href="{_href(readme, out)}">handout</a>' if readme.is_file() else ""
        sections.append(f'<section id="{lab}"><h2>{lab}{handout}</h2>'
                        + (f"<h3>views (open, then play, orbit, compare)</h3><ul>{items}</ul>" if items else "")
                        + (f'<h3>figures</h3><div class="thumbs">{thumbs}</div>' if thumbs else "")
                        + "</section>")
    contents = "".join(f'<a href="#{lab}">{lab[:5]}</a> ' for lab in lab_dirs() if (out / lab).is_dir())
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Constraint Labs: the course's runs</title>
<style>
body {{ font: 14px sans-serif; margin: 1em 2em; color: #222; }}
.thumbs img {{ height: 150px; margin: 4px; border: 1px solid #ccc; }}
h2 {{ border-bottom: 1px solid #ccc; }}
</style></head><body>
<h1>Constraint Labs: the course's runs</h1>
<p>Every lab's figures and views from <code>./course demo</code>. A view is one file: it plays the run's
frames (play, step, slider, speed, loop), orbits (drag), zooms (wheel) and pans (right drag); springs are
coloured by strain. Make your own with <code>./course view DIR [DIR2]</code>.</p>
<p>{contents}</p>
{"".join(sections)}
</body></html>
"""


def write_index(out):
    path = out / "index.html"
    path.write_text(index_page(out), encoding="utf-8")
    return path


def index_links(out):
    """Every href and src of out/index.html that does not resolve to a file."""
    missing = []

    class Links(HTMLParser):
        def handle_starttag(self, tag, attrs):
            for name, value in attrs:
                if name in ("href", "src") and value and not value.startswith("#"):
                    if not (out / value).is_file():
                        missing.append(value)

    Links().feed((out / "index.html").read_text(encoding="utf-8"))
    return missing


def summaries(out):
    """Run summaries (JSON with "lab" and "seconds") in OUT/<lab>/*.json."""
    found = []
    for path in sorted(out.glob("lab[0-9][0-9]_*/*.json")):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(data, dict) and "lab" in data and "seconds" in data:
            found.append(data)
    return found


def cell(value, fmt="{:.3g}"):
    """A table cell: numbers formatted, a missing value as `-`."""
    if value is None:
        return "-"
    return fmt.format(value) if isinstance(value, (int, float)) else str(value)


def outcome(summary):
    """What a run reported about itself: its "outcome", or "diverged", or nothing."""
    if "outcome" in summary:
        return str(summary["outcome"])
    return "diverged" if summary.get("diverged") else ""


def print_summary_table(out):
    rows = [[cell(s["lab"]), cell(s.get("scene")), cell(s.get("method")),
             cell(s.get("iterations"), "{}"), cell(s.get("max_strain_error")),
             cell(s["seconds"]), outcome(s)]
            for s in summaries(out)]
    if not rows:
        return
    header = ["lab", "scene", "method", "iterations", "max_strain_error", "seconds", "outcome"]
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    print()
    for row in [header, *rows]:
        print("  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip())


def cmd_demo(argv):
    parser = argparse.ArgumentParser(prog="course demo")
    parser.add_argument("--out", default="out", help="output directory (default out/)")
    parser.add_argument("--quick", action="store_true",
                        help="the shorter runs ./course test makes (demo.txt's `# quick:` lengths)")
    args = parser.parse_args(argv)
    out = under_root(args.out)
    run_demos(out, quick=args.quick)
    outcomes = run_plots(out)
    write_views(out)
    index = write_index(out)
    print_summary_table(out)
    print(f"\noutputs: {show(out)}/; all of it on one page: {show(index)} (file://{index.resolve()})")
    return 1 if plots_failed(outcomes) else 0


def cmd_run(argv):
    if not argv or argv[0].startswith("-"):
        raise CourseError("usage: ./course run labNN [ARGS]  (labNN_solution: the reference, where solutions/ holds it)", code=2)
    token, solution = argv[0], argv[0].endswith("_solution")
    lab = resolve_lab(token.removesuffix("_solution"))
    configure(log=sys.stderr)
    if solution and not manifest().get(lab, {}).get("reference"):
        raise CourseError(f"{token}: this tree has no reference of {grade.lab_id(lab)} yet (solutions/{lab}/ "
                          f"comes after its deadline); run your own code: ./course run {grade.lab_id(lab)}", code=2)
    name = lab + ("_solution" if solution else "")
    try:
        build_targets([name], log=sys.stderr)
    except BuildFailure as failure:
        raise CourseError(f"{name} does not build", details=failure.lines) from None
    program = executable(name)
    return become(program, [str(program), *argv[1:]])
