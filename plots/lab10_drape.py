#!/usr/bin/env python3
"""Lab 10: the drape at equal cost, flat Gauss-Seidel (top row) against three
levels (bottom row), coloured by how far each edge is stretched (from the OBJ
frames of the `drape-levels-N` runs of the demo). Writes drape.png."""
from pathlib import Path

import _figures as figures
from _figures import plt
import _lab04_mesh as mesh  # the OBJ reader and the camera of lab 04's pictures

LAB = "lab10_hierarchical_pbd"
COMMAND = ("./course demo lab10  (or: " + figures.make_command(LAB, "--scene drape-32 --levels 3 --iterations-per-level 12 "
                                                      "--steps 150 --frames 15 "
                                                      "--out out/lab10_hierarchical_pbd/drape-levels-3") + ")")


def main(out_dir):
    lab_dir = Path(out_dir) / LAB
    runs = [d for d in sorted(lab_dir.glob("drape-levels-*")) if mesh.frame_paths(d)]
    if not runs:
        return figures.skip("lab10_drape", f"no OBJ frames in {lab_dir}/drape-levels-N/frames/; make them with {COMMAND}")
    target = lab_dir / "drape.png"
    if figures.up_to_date(target, [path for run_dir in runs for path in mesh.frame_paths(run_dir)]):
        return 0
    rows = []
    for run_dir in runs:
        paths = mesh.frame_paths(run_dir)
        rows.append((run_dir.name, mesh.Frame(paths[0]), [mesh.Frame(p) for p in mesh.pick(paths, 4)]))
    limits = mesh.limits_of([f for _, _, frames in rows for f in frames])
    columns = max(len(frames) for _, _, frames in rows)
    figure, axes = plt.subplots(len(rows), columns, figsize=(2.9 * columns + 0.9, 3.0 * len(rows)), squeeze=False)
    mapper = None
    for line, (name, rest, frames) in zip(axes, rows):
        levels = int(name.rsplit("-", 1)[1])
        for panel, frame in zip(line, frames):
            mapper = mesh.draw(panel, frame, rest, limits)
            panel.set_title(f"t = {frame.time:.2f} s", fontsize=9)
        line[0].set_ylabel("flat Gauss-Seidel" if levels == 1 else f"{levels} levels", fontsize=10)
    bar = figure.colorbar(mapper, ax=axes.ravel().tolist(), fraction=0.02, pad=0.02)
    bar.set_label("edge stretch |l / l0 − 1| (log)")
    figure.suptitle(f"{rows[0][1].scene} at equal cost per step: the coarse levels pull the stretch out "
                    "and still let the cloth fold", fontsize=10)
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
