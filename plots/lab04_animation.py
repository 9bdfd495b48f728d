#!/usr/bin/env python3
"""Lab 04: an animated GIF of a whole run from its OBJ frames (`lab04_pbd
--frames N`), coloured by edge stretch. At most 40 frames of 360 x 360 pixels,
so that a GIF takes a few seconds to draw.

    plots/lab04_animation.py OUTDIR

One GIF per run directory with frames: OUTDIR/lab04_pbd/<run>/animation.gif."""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from PIL import Image  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _lab04_mesh as mesh  # noqa: E402

MAX_FRAMES = 40
PIXELS = 360
DPI = 72


def animate(run_dir):
    paths = mesh.frame_paths(run_dir)
    rest = mesh.Frame(paths[0])
    frames = [mesh.Frame(p) for p in mesh.pick(paths, MAX_FRAMES)]
    limits = mesh.limits_of(frames)
    figure, axes = plt.subplots(figsize=(PIXELS / DPI, PIXELS / DPI), dpi=DPI)
    figure.subplots_adjust(left=0.02, right=0.98, bottom=0.02, top=0.92)
    images = []
    for frame in frames:
        axes.clear()
        mesh.draw(axes, frame, rest, limits)
        axes.set_title(f"{frame.scene}   t = {frame.time:.2f} s", fontsize=11)
        figure.canvas.draw()
        rgba = Image.frombuffer("RGBA", figure.canvas.get_width_height(), figure.canvas.buffer_rgba())
        images.append(rgba.convert("RGB").quantize(colors=128))
    plt.close(figure)
    # Real time: the simulated time between the frames shown, at least 40 ms.
    step = (frames[-1].time - frames[0].time) / max(len(frames) - 1, 1)
    duration = max(40, int(round(1000 * step)))
    target = run_dir / "animation.gif"
    images[0].save(target, save_all=True, append_images=images[1:], duration=duration, loop=0, optimize=True)
    print(f"wrote {target} ({len(images)} frames, {duration} ms each)")


def main(argv):
    out_dir = argv[0] if argv else "out"
    runs = mesh.frame_dirs(out_dir)
    if not runs:
        lab_dir = Path(out_dir) / mesh.LAB
        print(f"lab04_animation: needs OBJ frames in {lab_dir}/RUN/frames/; make them with: ./course run "
              f"lab04_solution --scene curtain-32 --iterations 16 --steps 90 --frames 2 --out {lab_dir}/curtain-32")
        return 4
    for run_dir in runs:
        animate(run_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
