#!/usr/bin/env python3
"""The speed/accuracy trade (issue 12): per scene, error against wall time per
step for every method and iteration count, the Pareto front highlighted. Top
row: max strain error; middle row: distance to the converged reference step,
relative to the step's displacement; bottom row (when trade.csv has it): the
same for the hard step, the hard family's own target; then (when trade.csv has
them) the step's residual and the hard step's, each over the shared start's,
with their targets 1e-3 and 1e-6 (a residual is 0 at every solution alike, so
it resolves every scene). Where a scene's step has two minimisers
(trade_scenes.csv's reference_spread and hard_spread), the distances below
their spread are shaded: unresolved. Reads
OUTDIR/bench/trade.csv and trade_scenes.csv, writes OUTDIR/bench/pareto.png."""
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
    spread = {}  # (measure, scene) -> the two routes' spread, where it is above round-off
    if scene_table.exists():
        for r in figures.rows(scene_table):
            for key, column in (("relative_distance", "reference_spread"), ("relative_distance_hard", "hard_spread")):
                value = float(r.get(column) or "nan")
                if math.isfinite(value) and value > 1e-6:
                    spread[(key, r["scene"])] = value
    rows = [r for r in figures.rows(table) if not r["problem"]]
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    colors = {m: plt.cm.tab20(i % 20) for i, m in enumerate(methods)}
    distance_levels, residual_levels = (1e-2, 1e-3), (1e-3, 1e-6)
    measures = [("max_strain", "max strain error", distance_levels),
                ("relative_distance", "distance to reference step\n/ step displacement", distance_levels)]
    optional = [("relative_distance_hard", "distance to hard step\n/ its displacement", distance_levels),
                ("relative_residual", "step residual Δt²‖∇g‖_M⁻¹\n/ the start's", residual_levels),
                ("relative_residual_hard", "hard step residual\n/ the start's", residual_levels)]
    measures += [m for m in optional if rows and m[0] in rows[0]]
    figure, axes = plt.subplots(len(measures), len(scenes), figsize=(3.9 * len(scenes), 3.8 * len(measures)),
                                squeeze=False)
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
    handles, labels = axes[0][-1].get_legend_handles_labels()
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    figure.legend(handles, labels, loc="lower center", ncol=min(len(labels), 5), fontsize=8)
    figure.suptitle("Error against time per step: one step from a shared state, K growing along each line "
                    "(circles: the Pareto front)", fontsize=11)
    figure.tight_layout(rect=(0, 0.09, 1, 0.96))
    figures.save(figure, target, dpi=100)
    return 0


if __name__ == "__main__":
    figures.run(main)
