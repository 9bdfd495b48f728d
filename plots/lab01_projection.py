#!/usr/bin/env python3
"""Lab 01: before and after one projection pass, drawn in the x-y plane, one
panel per demo scene (each OUT/lab01_single_spring/<scene>/ with positions.csv
and springs.csv)."""
import math
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab01_single_spring"


def draw_case(axes, name, positions, springs):
    for when, style, alpha in (("before", "--", 0.45), ("after", "-", 1.0)):
        for spring in springs:
            i, j = int(spring["i"]), int(spring["j"])
            axes.plot([positions[i][f"x_{when}"], positions[j][f"x_{when}"]],
                      [positions[i][f"y_{when}"], positions[j][f"y_{when}"]],
                      style, color="C0", alpha=alpha, lw=1.5)
    for particle in positions:
        pinned = particle["inv_mass"] == 0.0
        marker = "s" if pinned else "o"
        axes.plot(particle["x_before"], particle["y_before"], marker, mfc="none", mec="C1", ms=8)
        axes.plot(particle["x_after"], particle["y_after"], marker, color="C3", ms=5)
        dx = particle["x_after"] - particle["x_before"]
        dy = particle["y_after"] - particle["y_before"]
        if math.hypot(dx, dy) > 0.0:
            axes.annotate("", xy=(particle["x_after"], particle["y_after"]),
                          xytext=(particle["x_before"], particle["y_before"]),
                          arrowprops={"arrowstyle": "->", "color": "0.3"})
    worst = max((spring["strain_after"] for spring in springs), default=0.0)
    axes.set_title(f"{name}\nmax strain after: {worst:.1e}", fontsize=9)
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.margins(0.25)


def main(out_dir):
    lab_dir = Path(out_dir) / LAB
    cases = sorted(p for p in lab_dir.glob("*") if (p / "positions.csv").exists() and (p / "springs.csv").exists())
    if not cases:
        return figures.skip("lab01_projection", f"needs {lab_dir}/SCENE/positions.csv and springs.csv; make them "
                            "with: " + figures.make_command(LAB, f"--scene triangle --out {lab_dir}/triangle")
                            + " (every scene: ./course demo lab01)")
    target = lab_dir / "projection_before_after.png"
    if figures.up_to_date(target, [c / name for c in cases for name in ("positions.csv", "springs.csv")]):
        return 0
    columns = min(3, len(cases))
    rows = math.ceil(len(cases) / columns)
    figure, grid = plt.subplots(rows, columns, figsize=(4.0 * columns, 3.8 * rows), squeeze=False)
    for axes, case in zip(grid.flat, cases):
        draw_case(axes, case.name, figures.numeric_rows(case / "positions.csv"),
                  figures.numeric_rows(case / "springs.csv"))
    for axes in list(grid.flat)[len(cases):]:
        axes.axis("off")
    figure.suptitle("One projection per spring: before (hollow, dashed) and after (filled, solid); squares are pinned")
    figure.tight_layout()
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
