"""./course demo and ./course run: the labs' executables; the demo's views
(./course view of every run that kept a trajectory, and demo.txt's `view:`
comparisons) and out/index.html, the page that links them all.

`./course demo` runs every lab that has a reference in this tree with it;
`./course demo labNN` runs one lab's demo.txt with the student's own code, so
that a week's tree shows the week's lab. Either exits 0 whatever out/ holds:
only the labs it ran get views and figures, and the index names the others
and why (docs/DESIGN.md §3, "The trajectory"; §4, "Release")."""
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

NOT_WRITTEN = 3  # a program's exit code when a student function is not written yet (docs/DESIGN.md §3)


class Demo:
    """What a demo did: the labs whose runs all ended (`ran`) and, for each lab
    it did not show, why, in one line (`skipped`); `failed` when a student's
    program failed (exit 1 at the end)."""

    def __init__(self):
        self.ran, self.skipped, self.failed = [], {}, False

    def skip(self, lab, why, echo=True):
        self.skipped[lab] = why
        if echo:
            print(f"  {grade.lab_id(lab)}: {why}", flush=True)


def run_demos(out, echo=True, labs=None, quick=False, own=()):
    """Run the demo lines of `labs` (default: every lab) into OUT/<lab>; return
    a Demo. A lab runs with its reference executable, or with the student's own
    (labNN) when it is in `own`. A lab without a reference here (in a student
    release: the week's lab and the later ones) is skipped, all of them named
    in one line: a stub would only exit 3. With the student's code, a function
    not written yet (exit 3) or code that does not compile skips that lab in
    one line and the demo goes on; a run that fails otherwise does too, and
    marks the demo failed. A failing reference run raises (CourseError).
    `quick`: demo.txt's `# quick:` lengths (labs.demo_lines)."""
    configure()
    entries = manifest()
    demo = Demo()
    labs = [lab for lab in (labs or lab_dirs()) if demo_lines(lab) and lab in entries]
    if not labs:
        print("no lab has a demo.txt yet")
    absent = [lab for lab in labs if lab not in own and not entries[lab]["reference"]]
    if absent:
        print(f"  demo skipped for {', '.join(grade.lab_id(lab) for lab in absent)}: no reference in this tree "
              f"yet (solutions/ gets it after the deadline); run it with your own code: ./course demo "
              f"{grade.lab_id(absent[0])}", flush=True)
    for lab in absent:  # in a release: the week's lab, then the later weeks'
        demo.skip(lab, f"no reference in this tree yet; ./course demo {grade.lab_id(lab)} runs it with your code"
                  if lab == absent[0] else "a later lab: no reference in this tree yet", echo=False)
    for lab in labs:
        if lab not in absent and run_lab_demo(demo, lab, out / lab, lab in own, echo, quick):
            demo.ran.append(lab)
    return demo


def run_lab_demo(demo, lab, lab_out, own, echo, quick):
    """One lab's demo.txt into LAB_OUT; True when every run ended (exit 0)."""
    name = lab if own else lab + "_solution"
    try:
        build_targets([name], log=None)
    except BuildFailure as failure:
        if not own:
            raise CourseError(f"{name} does not build", details=failure.lines) from None
        demo.failed = True
        demo.skip(lab, f"your code does not compile (./course grade {grade.lab_id(lab)} shows the errors)")
        return False
    program = executable(name)
    lab_out.mkdir(parents=True, exist_ok=True)
    for args in demo_lines(lab, quick):
        shown = shlex.join([program.name, *(a.replace("{out}", show(lab_out)) for a in args)])
        if echo:
            print("  " + shown, flush=True)
        argv = [str(program), *(arg.replace("{out}", str(lab_out)) for arg in args)]
        done = subprocess.run(argv, cwd=ROOT, capture_output=True, encoding="utf-8", errors="replace", check=False)
        if done.returncode == 0:
            continue
        said = done.stderr.strip().splitlines()
        if not own:
            raise CourseError(f"{shown} exited with code {done.returncode}", details=said)
        if done.returncode == NOT_WRITTEN:
            demo.skip(lab, f"your code is not written yet ({said[-1] if said else 'exit 3'})")
        else:
            demo.failed = True
            demo.skip(lab, f"{shown} exited with code {done.returncode}"
                           f"{': ' + said[-1] if said else ''}")
        return False
    return True


def demo_folders(lab, frames_only=False):
    """The folders LAB's demo.txt runs write (`--out {out}/X`), as X; with
    frames_only, those that keep a trajectory (--frames)."""
    found = set()
    for args in demo_lines(lab):
        for flag, value in zip(args, args[1:]):
            if flag == "--out" and value.startswith("{out}/") and (not frames_only or "--frames" in args):
                found.add(value[len("{out}/"):])
    return found


def write_views(out, labs=None, echo=True):
    """The views of OUT/<lab> for `labs` (default every lab): DIR/view.html for
    every DIR with a trajectory, and OUT/<lab>/view-A-vs-B.html for each
    `view: {out}/A {out}/B` line of the lab's demo.txt. Returns (the paths
    written, the folders refused with why). A refusal raises (CourseError)
    where the demo's own runs wrote the folder; elsewhere (a run of the
    student's own, in OUT/<lab>/) it is only reported."""
    written, refused = [], []
    for lab in labs if labs is not None else lab_dirs():
        lab_out = out / lab
        if not lab_out.is_dir():
            continue
        ours = {lab_out / folder for folder in demo_folders(lab)}
        for header in sorted(lab_out.rglob("trajectory.json")):
            try:
                written.append(write_view([header.parent]))
            except CourseError as error:
                if header.parent in ours:
                    raise
                refused.append(str(error))
        for dirs in view_lines(lab):
            folders = [Path(d.replace("{out}", str(lab_out))) for d in dirs]
            written.append(write_view(folders, lab_out / comparison_name(*folders)))
    if echo:
        for path in written:
            print(f"  view: {show(path)}")
        for why in refused:
            print(f"  not a view: {why}")
    return written, refused


def _href(path, out):
    """A link from out/index.html to `path`."""
    return html.escape(os.path.relpath(path, out).replace(os.sep, "/"), quote=True)


def skipped_section(demo):
    """The index's list of the labs this demo did not show, each with why."""
    if demo is None or not demo.skipped:
        return ""
    items = "".join(f"<li><b>{html.escape(lab)}</b>: {html.escape(why)}</li>" for lab, why in demo.skipped.items())
    return (f'<section id="skipped"><h2>not shown by this demo</h2><p>Their views were not written; '
            f"what out/ already held for them is listed below as it was.</p><ul>{items}</ul></section>")


def index_page(out, demo=None):
    """out/index.html's text: what the demo skipped and why; per lab, its
    views, its figures (thumbnails) and its handout."""
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
<p>The figures and views of <code>./course demo</code> (every lab that has a reference here, run with it)
and <code>./course demo labNN</code> (one lab, run with your own code). A view is one file: it plays the run's
frames (play, step, slider, speed, loop), orbits (drag), zooms (wheel) and pans (right drag); springs are
coloured by strain. Make your own with <code>./course view DIR [DIR2]</code>.</p>
<p>{contents}</p>
{skipped_section(demo)}
{"".join(sections)}
</body></html>
"""


def write_index(out, demo=None):
    path = out / "index.html"
    path.write_text(index_page(out, demo), encoding="utf-8")
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


def summaries(out, labs=None):
    """Run summaries (JSON with "lab" and "seconds") in OUT/<lab>/*.json (of `labs`: all)."""
    found = []
    for path in sorted(out.glob("lab[0-9][0-9]_*/*.json")):
        if labs is not None and path.parent.name not in labs:
            continue
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


def print_summary_table(out, labs=None):
    rows = [[cell(s["lab"]), cell(s.get("scene")), cell(s.get("method")),
             cell(s.get("iterations"), "{}"), cell(s.get("max_strain_error")),
             cell(s["seconds"]), outcome(s)]
            for s in summaries(out, labs)]
    if not rows:
        return
    header = ["lab", "scene", "method", "iterations", "max_strain_error", "seconds", "outcome"]
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    print()
    for row in [header, *rows]:
        print("  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip())


def cmd_demo(argv):
    parser = argparse.ArgumentParser(prog="course demo")
    parser.add_argument("labs", nargs="*", metavar="labNN",
                        help="these labs' demos with your own code (labNN_solution: the reference, where "
                             "solutions/ holds it); default: every lab that has a reference, run with it")
    parser.add_argument("--out", default="out", help="output directory (default out/)")
    parser.add_argument("--quick", action="store_true",
                        help="the shorter runs ./course test makes (demo.txt's `# quick:` lengths)")
    args = parser.parse_args(argv)
    out = under_root(args.out)
    labs, own = None, []
    if args.labs:
        labs = list(dict.fromkeys(resolve_lab(token.removesuffix("_solution")) for token in args.labs))
        own = [resolve_lab(token) for token in args.labs if not token.endswith("_solution")]
        configure()
        for token in args.labs:
            lab = resolve_lab(token.removesuffix("_solution"))
            if token.endswith("_solution") and not manifest().get(lab, {}).get("reference"):
                raise CourseError(f"{token}: this tree has no reference of {grade.lab_id(lab)} yet; "
                                  f"./course demo {grade.lab_id(lab)} runs it with your code", code=2)
            if not demo_lines(lab):
                raise CourseError(f"{grade.lab_id(lab)} has no demo (labs/{lab}/demo.txt)", code=2)
    demo = run_demos(out, labs=labs, quick=args.quick, own=own)
    # Only the labs that ran: the others' folders hold what the student's own
    # commands wrote there (a handout's experiment, without a trajectory).
    outcomes = run_plots(out, prefixes=[grade.lab_id(lab) for lab in demo.ran]) if demo.ran else {}
    write_views(out, demo.ran)
    index = write_index(out, demo)
    print_summary_table(out, demo.ran)
    print(f"\noutputs: {show(out)}/; all of it on one page: {show(index)} (file://{index.resolve()})")
    return 1 if plots_failed(outcomes) or demo.failed else 0


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
