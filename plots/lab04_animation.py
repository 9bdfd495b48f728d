#!/usr/bin/env python3
"""Lab 04: an animated GIF of a whole run from its OBJ frames (`lab04_pbd
--frames N`), coloured by edge stretch. At most 40 frames of 360 x 360 pixels,
so that a GIF takes a few seconds to draw.

    plots/lab04_animation.py OUTDIR

One GIF per run directory with frames: OUTDIR/lab04_pbd/<run>/animation.gif."""

import _figures as figures
import _lab04_mesh as mesh
from _figures import plt

MAX_FRAMES = 40
PIXELS = 360
DPI = 72


def animate(run_dir, target):
    from PIL import Image
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
    images[0].save(target, save_all=True, append_images=images[1:], duration=duration, loop=0, optimize=True)
    print(f"wrote {target} ({len(images)} frames, {duration} ms each)")


def main(out_dir):
    runs = mesh.frame_dirs(out_dir)
    if not runs:
        lab_dir = out_dir / mesh.LAB
        return figures.skip("lab04_animation", f"needs OBJ frames in {lab_dir}/RUN/frames/; make them with: "
                            + figures.make_command(mesh.LAB, "--scene curtain-32 --iterations 16 --steps 90 "
                                                   f"--frames 2 --out {lab_dir}/curtain-32"))
    for run_dir in runs:
        target = run_dir / "animation.gif"
        if not figures.up_to_date(target, mesh.frame_paths(run_dir)):
            animate(run_dir, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
