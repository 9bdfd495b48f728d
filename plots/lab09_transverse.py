#!/usr/bin/env python3
"""Lab 09: how fast the constraints turn (the max transverse speed) and how
far they are from their lengths, against time, for every single run
(per_frame.csv of `lab09_stable_constrained --out DIR`). Runs of the same
scene are drawn together, so the geometric stiffness on and off sit side by
side; a run that stopped ends where it stopped (marked x).

Writes OUTDIR/lab09_stable_constrained/transverse-<scene>.png per scene."""
from collections import defaultdict
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab09_stable_constrained"
COMMAND = "./course demo lab09 (or ./course run lab09 --scene heavy-chain-1000 --out out/lab09_stable_constrained/heavy-chain-1000-on)"
FLOOR = 1e-17  # log axes: exact zeros drawn here


def load(source):
    return figures.rows(source), figures.summary(source.parent.with_suffix(".json"))


def main(out_dir):
    folder = Path(out_dir) / LAB
    sources = sorted(folder.glob("*/per_frame.csv"))
    if not sources:
        return figures.skip("lab09_transverse", f"no {folder}/*/per_frame.csv (make them with {COMMAND})")
    by_scene, inputs = defaultdict(list), defaultdict(list)
    for source in sources:
        rows, summary = load(source)
        by_scene[summary.get("scene", source.parent.name)].append((source.parent.name, rows, summary))
        inputs[summary.get("scene", source.parent.name)] += [source, source.parent.with_suffix(".json")]
    for scene, runs in sorted(by_scene.items()):
        target = folder / f"transverse-{scene}.png"
        if figures.up_to_date(target, inputs[scene]):
            continue
        figure, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.0))
        for name, rows, summary in runs:
            finite = [r for r in rows if r["max_transverse_speed"] not in ("", "nan", "inf")]
            if not finite:
                continue
            time = [float(r["time"]) for r in finite]
            speed = [max(float(r["max_transverse_speed"]), FLOOR) for r in finite]
            error = [max(float(r["max_constraint_error"]), FLOOR) for r in finite]
            label = name
            if summary:
                label = f"K_g {summary.get('geometric_stiffness')}, {summary.get('method')}"
                if summary.get("compression") == "keep":
                    label += ", compression kept"
            (line,) = left.semilogy(time, speed, label=label)
            right.semilogy(time, error, color=line.get_color(), label=label)
            if finite[-1]["status"] != "ok":
                left.semilogy(time[-1], speed[-1], "x", ms=9, mew=2, color=line.get_color())
                right.semilogy(time[-1], error[-1], "x", ms=9, mew=2, color=line.get_color())
        left.set_xlabel("time (s)")
        left.set_ylabel("max transverse speed (m/s)")
        right.set_xlabel("time (s)")
        right.set_ylabel("max |φ| (m)")
        for axes in (left, right):
            axes.grid(True, which="both", alpha=0.3)
            axes.legend(fontsize=8)
        dt = runs[0][2].get("dt")
        figure.suptitle(f"{scene}" + (f", Δt = {dt:.4g} s" if dt else "") + "  (x: the run stopped there)",
                        fontsize=11)
        figure.tight_layout()
        figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
