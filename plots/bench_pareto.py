#!/usr/bin/env python3
"""The speed/accuracy trade (issue 12): per scene, error against wall time per
step for every method and iteration count, the Pareto front highlighted. One
panel per start (trade.csv's `start`: the trajectory start, then the rough
one), one column per scene. Rows: the max strain error; the step's residual
over the start's, with its targets 1e-3 and 1e-6 (0 at every solution alike,
so it resolves every scene); the distance to the converged reference step,
relative to the step's displacement. Where a scene's step has two minimisers
(trade_scenes.csv's reference_spread), the distances below the spread are
shaded: unresolved. (The hard step's distance and residual are in the CSV and
bench/README.md's tables.) Reads OUTDIR/bench/trade.csv and trade_scenes.csv,
writes OUTDIR/bench/pareto.png."""
import math
from pathlib import Path

import _figures as figures
from _figures import plt

COMMAND = "./course bench  (or: build/bin/trade --out out/bench)"
FAMILY_MARKER = {"hard": "s", "implicit-euler": "o", "linearized": "D", "limited": "v"}


def front(points):
    """The points no other point beats in both coordinates (time, error), fastest first."""
    kept, best = [], float("inf")
    for t, e in sorted(points):
        if e < best:
            kept.append((t, e))
            best = e
    return kept


def main(out_dir):
    bench = Path(out_dir) / "bench"
    table = bench / "trade.csv"
    if not table.exists():
        return figures.skip("bench_pareto", f"no {table}; make it with {COMMAND}")
    target = bench / "pareto.png"
    scene_table = bench / "trade_scenes.csv"
    if figures.up_to_date(target, [table] + ([scene_table] if scene_table.exists() else [])):
        return 0
    spread = {}  # (measure, scene, start) -> the two routes' spread, where it is above round-off
    if scene_table.exists():
        for r in figures.rows(scene_table):
            for key, column in (("relative_distance", "reference_spread"), ("relative_distance_hard", "hard_spread")):
                value = float(r.get(column) or "nan")
                if math.isfinite(value) and value > 1e-6:
                    spread[(key, r["scene"], r.get("start") or "rough")] = value
    rows = [r for r in figures.rows(table) if not r["problem"]]
    for r in rows:
        r.setdefault("start", "rough")  # runs before the column were from the rough start
        r["start"] = r["start"] or "rough"
    starts = [s for s in ("trajectory", "rough") if any(r["start"] == s for r in rows)]
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    colors = {m: plt.cm.tab20(i % 20) for i, m in enumerate(methods)}
    distance_levels, residual_levels = (1e-2, 1e-3), (1e-3, 1e-6)
    measures = [("max_strain", "max strain error", distance_levels)]
    if rows and "relative_residual" in rows[0]:
        measures.append(("relative_residual", "step residual Δt²‖∇g‖_M⁻¹\n/ the start's", residual_levels))
    measures.append(("relative_distance", "distance to reference step\n/ step displacement", distance_levels))
    panel_height = 3.6 * len(measures)
    figure = plt.figure(figsize=(3.9 * len(scenes), panel_height * len(starts) + 1.8))
    # One subfigure per start, and one for the legend below them.
    parts = figure.subfigures(len(starts) + 1, 1, squeeze=False,
                              height_ratios=[panel_height] * len(starts) + [1.8])[:, 0]
    all_axes = []
    for start, panel in zip(starts, parts):
        axes = panel.subplots(len(measures), len(scenes), squeeze=False)
        all_axes.append(axes)
        panel.suptitle(f"From the {start} start" + (" (10 accurate steps from rest)" if start == "trajectory"
                                                    else " (10 steps of PD, 100 iterations: compressed and folded)")
                       + "\nerror against time per step, K growing along each line (circles: the Pareto front)",
                       fontsize=11)
        draw_panel(axes, [r for r in rows if r["start"] == start], scenes, methods, colors, measures,
                   {(key, scene): value for (key, scene, s), value in spread.items() if s == start})
    handles, labels = [], []
    for axes in all_axes:
        for ax in axes.flat:
            for h, lab in zip(*ax.get_legend_handles_labels()):
                if lab not in labels:
                    handles.append(h)
                    labels.append(lab)
    parts[-1].legend(handles, labels, loc="center", ncol=min(len(labels), 5), fontsize=8)
    figures.save(figure, target, dpi=80)
    return 0


def draw_panel(axes, rows, scenes, methods, colors, measures, spread):
    """One start's grid: a column per scene, a row per measure."""
    for column, scene in enumerate(scenes):
        mine = [r for r in rows if r["scene"] == scene]
        for row, (key, label, levels) in enumerate(measures):
            ax = axes[row][column]
            for method in methods:
                runs = sorted((r for r in mine if r["method"] == method and math.isfinite(float(r[key]))),
                              key=lambda r: int(r["iterations"]))
                if not runs:
                    continue
                t = [float(r["step_seconds"]) for r in runs]
                e = [max(float(r[key]), 1e-16) for r in runs]
                ax.loglog(t, e, "-", marker=FAMILY_MARKER.get(runs[0]["family"], "o"), markersize=4,
                          color=colors[method], alpha=0.85, label=f"{method} ({runs[0]['family']})")
            best = front([(float(r["step_seconds"]), max(float(r[key]), 1e-16)) for r in mine
                          if math.isfinite(float(r[key]))])
            ax.step([p[0] for p in best], [p[1] for p in best], where="post", color="black", linewidth=1.2,
                    zorder=0, label="Pareto front")
            ax.scatter([p[0] for p in best], [p[1] for p in best], s=70, facecolors="none", edgecolors="black",
                       linewidths=1.2, zorder=5)
            for level in levels:
                ax.axhline(level, color="gray", linestyle=":", linewidth=0.8)
            if (key, scene) in spread:
                level = spread[(key, scene)]
                low, high = ax.get_ylim()  # the span must not stretch the axis down to round-off
                ax.axhspan(low, level, color="gray", alpha=0.15, zorder=0,
                           label="unresolved: the step has two minimisers this far apart")
                ax.set_ylim(low, max(high, 2.0 * level))
            ax.set_xlabel("wall time per step (s)")
            if column == 0:
                ax.set_ylabel(label)
            if row == 0:
                ax.set_title(scene)
            ax.grid(True, which="major", alpha=0.3)


if __name__ == "__main__":
    figures.run(main)
