"""./course view DIR [DIR2]: one self-contained HTML player of a run's
trajectory (DIR/trajectory.json and .bin, written by --frames N), or of two
runs side by side with one clock and one camera (docs/DESIGN.md §3, "The
trajectory", and §7).

The page inlines the course's copy of three.js r111 and its OrbitControls
(tools/cl/vendor/three/, from npm's three@0.111.0) and embeds the data as base64, so it opens from disk with no server and no
network. It writes its state into <body>'s attributes (data-frames,
data-particles, data-springs, data-frame, data-sample, data-ready, data-error)
for the browser test in ./course test (checks.py).
"""
import argparse
import base64
import json
import os
import tempfile
from pathlib import Path

from .base import CourseError, show, under_root

THREE_DIR = Path(__file__).with_name("vendor") / "three"  # npm's three@0.111.0 (its README.md)
THREE_FILES = [THREE_DIR / "three.min.js", THREE_DIR / "OrbitControls.js"]
PLAYER = Path(__file__).with_name("view_player.js")


def refuse(message):
    return CourseError(message, code=2)


def load_run(folder):
    """(header, data) of FOLDER's trajectory, checked; CourseError (exit 2, one
    line naming the file) for a folder without one, a corrupt header or a
    truncated trajectory.bin."""
    folder = Path(folder)
    path = folder / "trajectory.json"
    if not path.is_file():
        raise refuse(f"{show(folder)}: no trajectory.json (run the lab with --frames N --out {show(folder)})")
    try:
        header = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise refuse(f"{show(path)}: not a trajectory ({error})") from None
    problem = header_problem(header)
    if problem:
        raise refuse(f"{show(path)}: corrupt trajectory: {problem}")
    data_path = folder / header["bin"]
    try:
        data = data_path.read_bytes()
    except OSError:
        raise refuse(f"{show(data_path)}: missing (the header {show(path)} needs it)") from None
    expected = header["frame_count"] * header["frame_bytes"]
    if len(data) != expected:
        raise refuse(f"{show(data_path)}: {len(data)} bytes, the header says {expected} "
                     f"({header['frame_count']} frames of {header['frame_bytes']}): truncated or corrupt")
    return header, data


def header_problem(header):
    """What is wrong with a trajectory header (None: nothing)."""
    if not isinstance(header, dict) or header.get("format") != "cl-trajectory":
        return "no \"format\": \"cl-trajectory\""
    if header.get("version") != 1:
        return f"version {header.get('version')!r}, this view reads 1"
    for key, kind in [("particles", int), ("springs", list), ("triangles", list), ("pinned", list),
                      ("frames", list), ("frame_count", int), ("frame_bytes", int), ("bin", str)]:
        if not isinstance(header.get(key), kind):
            return f"\"{key}\" missing or not a {kind.__name__}"
    n, springs, frames = header["particles"], header["springs"], header["frames"]
    if n < 0 or len(springs) % 2 or len(header["triangles"]) % 3:
        return "particles < 0, or springs / triangles not in pairs / triples"
    for key in ("springs", "triangles", "pinned"):
        if any(not isinstance(i, int) or not 0 <= i < n for i in header[key]):
            return f"\"{key}\" has an index outside 0 … {n - 1}"
    if len(frames) != header["frame_count"]:
        return f"{len(frames)} frame records for \"frame_count\" {header['frame_count']}"
    if not frames:
        stopped = header.get("stopped") or {}
        return f"no frame kept (the run stopped at frame {stopped.get('frame', '?')}: {stopped.get('status', '?')})"
    needed = 6 * n + len(springs) // 2
    if header["frame_bytes"] != (needed + 3) // 4 * 4:
        return f"\"frame_bytes\" {header['frame_bytes']} does not fit {n} particles and {len(springs) // 2} springs"
    if Path(header["bin"]).name != header["bin"]:
        return "\"bin\" is not a file name beside the header"
    for k, frame in enumerate(frames):
        try:
            ok = (len(frame["box_min"]) == 3 and len(frame["step"]) == 3
                  and all(isinstance(v, (int, float)) for v in [*frame["box_min"], *frame["step"],
                                                                  frame["time"], frame["strain_scale"]]))
        except (KeyError, TypeError):
            ok = False
        if not ok:
            return f"frames[{k}]: needs box_min, step (3 numbers each), time and strain_scale"
    return None


def decode_positions(header, data, k):
    """Frame k's positions as decoded (m): a list of n (x, y, z); what the page shows."""
    n = header["particles"]
    frame = header["frames"][k]
    start = k * header["frame_bytes"]
    levels = memoryview(data)[start:start + 6 * n].cast("H")
    return [tuple(frame["box_min"][a] + levels[3 * p + a] * frame["step"][a] for a in range(3)) for p in range(n)]


def page(runs, title):
    """The HTML text: three.js, OrbitControls, the runs' data and the player."""
    for path in [*THREE_FILES, PLAYER]:
        if not path.is_file():
            raise CourseError(f"{show(path)} not found (it is part of the course's tree)")
    scripts = "\n".join(f"<script>\n{path.read_text(encoding='utf-8')}\n</script>" for path in THREE_FILES)
    data = []
    for r, (header, blob) in enumerate(runs):
        text = json.dumps(header, separators=(",", ":")).replace("</", "<\\/")
        data.append(f'<script type="application/json" id="run{r}">{text}</script>\n'
                    f'<script type="text/plain" id="bin{r}">{base64.b64encode(blob).decode()}</script>')
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
html, body {{ margin: 0; height: 100%; overflow: hidden; background: #f4f4f0; font: 13px sans-serif; }}
#hud {{ position: absolute; left: 8px; top: 6px; right: 8px; pointer-events: none; color: #222; }}
#hud .run {{ display: inline-block; vertical-align: top; width: 49%; white-space: pre-wrap; }}
#hud .run:only-child {{ width: 75%; }}
#hud .command {{ color: #666; font-size: 11px; }}
#controls {{ position: absolute; left: 8px; right: 8px; bottom: 8px; display: flex; gap: 8px; align-items: center; }}
#controls input[type=range] {{ flex: 1; }}
#bar {{ position: absolute; right: 10px; bottom: 44px; width: 150px; text-align: center; font-size: 11px; }}
#bar canvas {{ width: 150px; height: 12px; border: 1px solid #888; box-sizing: border-box; }}
#bar select {{ width: 100%; box-sizing: border-box; margin-top: 2px; font-size: 11px; }}
</style></head>
<body data-ready="0">
<script>
window.addEventListener('error', function (e) {{ document.body.setAttribute('data-error', String(e.message)); }});
(function () {{ var original = console.error; console.error = function () {{
  document.body.setAttribute('data-error', Array.prototype.join.call(arguments, ' ')); original.apply(console, arguments); }}; }})();
</script>
{scripts}
{chr(10).join(data)}
<div id="hud"></div>
<div id="bar"><div id="bar-title">strain (l − L)/L</div><canvas id="bar-canvas" width="150" height="12"></canvas>
<div><span id="bar-low" style="float:left"></span><span id="bar-high" style="float:right"></span>0</div>
<select id="scale" title="the colour scale: the largest |strain| of every frame, of the frame shown, or fixed">
<option value="run">scale: all frames</option><option value="frame">scale: this frame</option>
<option value="0.1">scale: 10 %</option><option value="0.01">scale: 1 %</option><option value="0.001">scale: 0.1 %</option></select></div>
<div id="controls">
<button id="back" title="previous frame (←)">&#9664;&#9646;</button>
<button id="play" title="play / pause (space)">play</button>
<button id="forward" title="next frame (→)">&#9646;&#9654;</button>
<input id="slider" type="range" min="0" max="0" value="0">
<span id="counter"></span>
<label>speed <select id="speed"><option>0.1</option><option>0.25</option><option>0.5</option>
<option selected>1</option><option>2</option><option>4</option></select></label>
<label><input id="loop" type="checkbox" checked> loop</label>
</div>
<script>
{PLAYER.read_text(encoding="utf-8")}
</script>
</body></html>
"""


def write_atomic(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=".view-", suffix=".html")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            out.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)  # mkstemp's 0600 would hide the page from a web server
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def comparison_name(first, second):
    """The file of a side-by-side view: view-A-vs-B.html, A and B the runs' folder names."""
    return f"view-{Path(first).name}-vs-{Path(second).name}.html"


def default_output(folders):
    """DIR/view.html for one run; for two, DIR's parent/view-A-vs-B.html, so that
    a comparison never overwrites the first run's own view (./course demo names
    its comparisons alike)."""
    if len(folders) == 1:
        return folders[0] / "view.html"
    return folders[0].resolve().parent / comparison_name(*folders)


def write_view(folders, output=None):
    """Write the view of one run or two (folders) to `output` (default:
    default_output); return its path. Refuses (CourseError, exit 2) before
    writing anything."""
    folders = [Path(f) for f in folders]
    runs = [load_run(f) for f in folders]
    output = Path(output) if output else default_output(folders)
    title = " vs ".join(f"{h['lab']} {h['scene']} {h['method']}" for h, _ in runs)
    write_atomic(output, page(runs, title.replace("<", "&lt;")))
    return output


def cmd_view(argv):
    parser = argparse.ArgumentParser(prog="course view",
                                     description="a self-contained 3-D player of a run's frames (--frames N --out DIR)")
    parser.add_argument("dirs", nargs="+", metavar="DIR", help="a run's --out folder; a second one: side by side")
    parser.add_argument("--output", help="the HTML file (default DIR/view.html; with DIR2 view-DIR-vs-DIR2.html "
                                         "beside DIR)")
    args = parser.parse_args(argv)
    if len(args.dirs) > 2:
        raise refuse("view: one run or two (DIR [DIR2]), not " + str(len(args.dirs)))
    path = write_view([under_root(d) for d in args.dirs], under_root(args.output) if args.output else None)
    size = path.stat().st_size / 2**20
    print(f"wrote {show(path)} ({size:.1f} MB); open it in a browser (file://{path.resolve()})")
    return 0
