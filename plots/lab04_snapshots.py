#!/usr/bin/env python3
"""Lab 04: snapshots of a run's mesh at chosen frames, coloured by how far each
edge is stretched (from the OBJ frames of `lab04_pbd --frames N`).

    plots/lab04_snapshots.py OUTDIR [--frames 0,60,120]

One PNG per run directory with frames: OUTDIR/lab04_pbd/<run>/snapshots.png.
With --frames: the nearest written frame to each; without: four frames
spread evenly over the run."""
import argparse
import sys
from pathlib import Path

import _figures as figures
from _figures import plt
import _lab04_mesh as mesh


def snapshot(run_dir, wanted, target):
    paths = mesh.frame_paths(run_dir)
    rest = mesh.Frame(paths[0])
    if wanted:  # the nearest written frame to each one asked for
        by_number = {int(p.stem.split("_")[1]): p for p in paths}
        chosen = [by_number[min(by_number, key=lambda written: abs(written - n))] for n in wanted]
    else:
        chosen = mesh.pick(paths, 4)
    frames = [mesh.Frame(p) for p in chosen]
    limits = mesh.limits_of(frames)
    figure, axes = plt.subplots(1, len(frames), figsize=(3.0 * len(frames) + 0.8, 3.6), squeeze=False)
    mapper = None
    for panel, frame in zip(axes[0], frames):
        mapper = mesh.draw(panel, frame, rest, limits)
        panel.set_title(f"t = {frame.time:.2f} s (frame {frame.frame})", fontsize=9)
    bar = figure.colorbar(mapper, ax=axes[0].tolist(), fraction=0.025, pad=0.02)
    bar.set_label("edge stretch |l / l0 − 1| (log)")
    figure.suptitle(f"{rest.scene}: position based dynamics (orthographic view, 1 m cloth)", fontsize=10)
    figures.save(figure, target)


def main(argv):
    parser = argparse.ArgumentParser(prog="lab04_snapshots.py")
    parser.add_argument("out_dir", nargs="?", default="out")
    parser.add_argument("--frames", default="", help="frame numbers, e.g. 0,60,120 (default: four, evenly spread)")
    args = parser.parse_args(argv)
    wanted = [int(n) for n in args.frames.split(",") if n.strip()]
    runs = mesh.frame_dirs(args.out_dir)
    if not runs:
        lab_dir = Path(args.out_dir) / mesh.LAB
        return figures.skip("lab04_snapshots", f"needs OBJ frames in {lab_dir}/RUN/frames/; make them with: "
                            + figures.make_command(mesh.LAB, "--scene curtain-32 --iterations 16 --steps 90 "
                                                   f"--frames 2 --out {lab_dir}/curtain-32"))
    for run_dir in runs:
        target = run_dir / "snapshots.png"
        if wanted or not figures.up_to_date(target, mesh.frame_paths(run_dir)):
            snapshot(run_dir, wanted, target)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
