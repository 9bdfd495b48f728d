#!/usr/bin/env python3
"""Lab 05, experiment 2: the stability map (from `lab05_strain_limiting
--stability-map`, stability_map.csv). One cell per (spring stiffness, Δt):

- stable: the explicit step alone stays healthy;
- bounded by the limiter: it blows up alone, and with the limiter every
  spring stays in the band (up to 0.5/K) for the whole run;
- blew up: the limited run went wrong too — reported unstable (solid), or
  finite but outside the band (hatched).

The dashed line is the program's estimate of the explicit step's limit,
Δt = 2 / √(8 k w). Writes stability_map.png beside the CSV."""
import math

import _figures as figures
from _figures import plt

LAB = "lab05_strain_limiting"
COMMAND = figures.make_command(LAB, "--scene map-curtain-16 --stability-map --out out/lab05_strain_limiting "
                               "(or ./course demo lab05)")
COLOURS = {"stable": "#5fae5f", "bounded by the limiter": "#5b8fd6", "blew up": "#d65b5b"}


def edges(values):
    """Cell edges on a log axis: geometric midpoints, half a step beyond the ends."""
    logs = [math.log10(v) for v in values]
    if len(logs) == 1:
        return [10 ** (logs[0] - 0.5), 10 ** (logs[0] + 0.5)]
    mids = [(a + b) / 2 for a, b in zip(logs, logs[1:])]
    return [10 ** (2 * logs[0] - mids[0])] + [10 ** m for m in mids] + [10 ** (2 * logs[-1] - mids[-1])]


def main(out_dir):
    source = out_dir / LAB / "stability_map.csv"
    if not source.is_file():
        return figures.skip("lab05_stability_map", f"no {source} (make it with {COMMAND})")
    target = source.with_name("stability_map.png")
    if figures.up_to_date(target, [source]):
        return 0
    from matplotlib.patches import Patch, Rectangle
    rows = figures.rows(source)
    dts = sorted({float(r["dt"]) for r in rows})
    stiffnesses = sorted({float(r["stiffness"]) for r in rows})
    dt_edges, k_edges = edges(dts), edges(stiffnesses)
    figure, axis = plt.subplots(figsize=(8.0, 5.6))
    for r in rows:
        i, j = dts.index(float(r["dt"])), stiffnesses.index(float(r["stiffness"]))
        verdict = r["verdict"]
        finite_outside = verdict == "blew up" and r["limited_status"] == "ok"
        axis.add_patch(Rectangle((dt_edges[i], k_edges[j]), dt_edges[i + 1] - dt_edges[i],
                                 k_edges[j + 1] - k_edges[j], facecolor=COLOURS.get(verdict, "0.7"),
                                 edgecolor="white", hatch="///" if finite_outside else None, lw=1.5))
        label = ""
        if r["limited_max_strain"]:
            strain = float(r["limited_max_strain"])
            label = f"{strain:.2f}" if strain < 100 else f"{strain:.0e}"
        axis.text(math.sqrt(dt_edges[i] * dt_edges[i + 1]), math.sqrt(k_edges[j] * k_edges[j + 1]), label,
                  ha="center", va="center", fontsize=8)
    # The estimated explicit limit: Δt = 2 / √(8 k w), from the CSV (no physics here).
    limit = sorted((float(r["stiffness"]), float(r["dt_explicit_estimate"])) for r in rows)
    axis.plot([d for _, d in limit], [k for k, _ in limit], "k--", lw=1.2, label="explicit limit (estimate)")
    axis.set_xscale("log")
    axis.set_yscale("log")
    axis.set_xlim(dt_edges[0], dt_edges[-1])
    axis.set_ylim(k_edges[0], k_edges[-1])
    axis.set_xlabel("time step Δt (s)")
    axis.set_ylabel("spring stiffness k (N/m)")
    first = rows[0]
    axis.set_title(f"{first['scene']}: limit {first['limit']}, band [{float(first['sigma_min']):g}, "
                   f"{float(first['sigma_max']):g}], K = {first['iterations']}\n"
                   "numbers: the limited run's max strain l/L − 1", fontsize=9)
    handles = [Patch(facecolor=c, label=v) for v, c in COLOURS.items()]
    handles.append(Patch(facecolor=COLOURS["blew up"], hatch="///", label="blew up: finite, but outside the band"))
    handles.append(axis.get_lines()[0])
    axis.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    figure.tight_layout()
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
