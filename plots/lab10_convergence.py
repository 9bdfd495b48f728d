#!/usr/bin/env python3
"""Lab 10, experiment 1: one step of the released curtain, the cloth's max
strain against the projections spent, flat Gauss-Seidel against 2-4 levels
(from `lab10_hierarchical_pbd --converge`, convergence.csv and to_target.csv
in OUTDIR/lab10_hierarchical_pbd/ and its curtain-128/ folder).

Writes convergence.png (the curves), to_target.png (projections to 5 % and
1 % against the resolution) and to_target.md (the table for the handout)."""
from collections import defaultdict
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab10_hierarchical_pbd"
COMMAND = ("./course demo lab10  (or: " + figures.make_command(LAB, "--converge --sweep-scenes flat-curtain-32,flat-curtain-64 "
           "--sweep-levels 1,2,3,4 --iterations-per-level 4 --out out/lab10_hierarchical_pbd)"))


def read(paths):
    return [row for path in paths if path.exists() for row in figures.rows(path)]


def level_label(levels):
    return "flat Gauss-Seidel" if levels == 1 else f"{levels} levels"


def draw_curves(samples, targets, target_path):
    by_scene = defaultdict(lambda: defaultdict(list))
    for r in samples:
        by_scene[(int(r["nx"]), r["scene"])][int(r["levels"])].append(r)
    scenes = sorted(by_scene)
    figure, axes = plt.subplots(1, len(scenes), figsize=(5.0 * len(scenes), 4.6), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for panel, key in zip(axes[0], scenes):
        for levels, rows in sorted(by_scene[key].items()):
            rows = [r for r in rows if int(r["projections"]) > 0]
            x = [int(r["projections"]) for r in rows]
            y = [float(r["max_strain"]) for r in rows]
            panel.loglog(x, y, "-", color=colours[levels - 1], label=f"{level_label(levels)} ({rows[0]['iterations_per_level']} sweeps/pass)")
        for t in targets:
            panel.axhline(t, color="0.5", ls=":", lw=1)
            panel.text(0.99, t * 1.04, f"target {t:g}", color="0.4", fontsize=8, ha="right", va="bottom",
                       transform=panel.get_yaxis_transform())
        panel.set_title(f"{key[1]} ({key[0]}² particles)", fontsize=10)
        panel.set_xlabel("constraint projections (coarse levels included)")
        panel.set_ylabel("max strain of the cloth  max |l − L| / L")
        panel.grid(True, which="major", alpha=0.3)
        panel.legend(fontsize=8)
    figure.suptitle("One step of the released curtain: convergence of the projection, flat GS against "
                    "hierarchical PBD", fontsize=11)
    figure.tight_layout(rect=(0, 0, 1, 0.95))
    figures.save(figure, target_path)


def draw_to_target(reached, target_path):
    targets = sorted({float(r["target"]) for r in reached}, reverse=True)
    figure, axes = plt.subplots(1, len(targets), figsize=(5.2 * len(targets), 4.4), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for panel, target in zip(axes[0], targets):
        rows = [r for r in reached if float(r["target"]) == target]
        for levels in sorted({int(r["levels"]) for r in rows}):
            mine = sorted((r for r in rows if int(r["levels"]) == levels), key=lambda r: int(r["nx"]))
            x = [int(r["nx"]) for r in mine]
            y = [int(r["projections"]) for r in mine]
            colour = colours[levels - 1]
            done_x = [xi for r, xi in zip(mine, x) if r["reached"] == "yes"]
            done_y = [yi for r, yi in zip(mine, y) if r["reached"] == "yes"]
            panel.loglog(x, y, ":", color=colour, lw=1)  # dotted where a point is only a lower bound
            panel.loglog(done_x, done_y, "-", color=colour, label=level_label(levels))
            for r, xi, yi in zip(mine, x, y):
                done = r["reached"] == "yes"
                panel.plot(xi, yi, "o" if done else "^", color=colour, mfc=colour if done else "white", ms=7)
        panel.plot([], [], "^", color="0.4", mfc="white", label="not reached: the cap (a lower bound)")
        panel.set_xscale("log", base=2)
        sizes = sorted({int(r["nx"]) for r in rows})
        panel.set_xticks(sizes)
        panel.set_xticklabels([f"{n}²" for n in sizes])
        panel.set_xlabel("curtain resolution (particles)")
        panel.set_ylabel("projections to reach the target")
        panel.set_title(f"max strain ≤ {target:g}", fontsize=10)
        panel.grid(True, which="major", alpha=0.3)
        panel.legend(fontsize=8)
    figure.suptitle("Cost of one step's projection to a strain target (4 sweeps per level and pass)", fontsize=11)
    figure.tight_layout(rect=(0, 0, 1, 0.94))
    figures.save(figure, target_path)


def markdown(reached):
    targets = sorted({float(r["target"]) for r in reached}, reverse=True)
    header = "| curtain | levels | " + " | ".join(f"to {t:g}: sweeps / projections / s" for t in targets) + " |"
    lines = [header, "|---|---:|" + "---:|" * len(targets)]
    keys = sorted({(int(r["nx"]), r["scene"], int(r["levels"])) for r in reached})
    for nx, scene, levels in keys:
        cells = []
        for t in targets:
            r = next(r for r in reached if r["scene"] == scene and int(r["levels"]) == levels and float(r["target"]) == t)
            if r["reached"] == "yes":
                cells.append(f"{r['sweeps']} / {int(r['projections']):.3g} / {float(r['seconds']):.3g}")
            else:
                cells.append(f"not in {r['sweeps']} ({float(r['max_strain']):.3g} left)")
        lines.append(f"| {nx}² | {levels} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(out_dir):
    lab_dir = Path(out_dir) / LAB
    sample_paths = [lab_dir / "convergence.csv", lab_dir / "curtain-128" / "convergence.csv"]
    target_paths = [lab_dir / "to_target.csv", lab_dir / "curtain-128" / "to_target.csv"]
    if not sample_paths[0].exists() or not target_paths[0].exists():
        return figures.skip("lab10_convergence", f"no {sample_paths[0]} or {target_paths[0]}; make them with {COMMAND}")
    samples, reached = read(sample_paths), read(target_paths)
    targets = sorted({float(r["target"]) for r in reached})
    if not figures.up_to_date(lab_dir / "convergence.png", sample_paths + target_paths):
        draw_curves(samples, targets, lab_dir / "convergence.png")
    if not figures.up_to_date([lab_dir / "to_target.png", lab_dir / "to_target.md"], target_paths):
        draw_to_target(reached, lab_dir / "to_target.png")
        figures.write_table(lab_dir / "to_target.md", markdown(reached))
    return 0


if __name__ == "__main__":
    figures.run(main)
