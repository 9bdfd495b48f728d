#!/usr/bin/env python3
"""The speed/accuracy trade (issue 12): wall time per iteration against the
curtain's size, log-log, with each method's fitted exponent p (time ~ n^p) in
the legend. Reads OUTDIR/bench/trade_scaling.csv, writes OUTDIR/bench/scaling.png."""
import math
from pathlib import Path

import _figures as figures
from _figures import plt

COMMAND = "./course bench  (or: build/bin/trade --out out/bench)"


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main(out_dir):
    bench = Path(out_dir) / "bench"
    table = bench / "trade_scaling.csv"
    if not table.exists():
        return figures.skip("bench_scaling", f"no {table}; make it with {COMMAND}")
    target = bench / "scaling.png"
    if figures.up_to_date(target, [table]):
        return 0
    rows = figures.rows(table)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    figure, ax = plt.subplots(figsize=(7.5, 5.4))
    for i, method in enumerate(methods):
        mine = sorted((r for r in rows if r["method"] == method), key=lambda r: int(r["particles"]))
        n = [int(r["particles"]) for r in mine]
        t = [float(r["seconds_per_iteration"]) for r in mine]
        label = method if len(n) < 2 else f"{method}: p = {slope(n, t):.2f}"
        ax.loglog(n, t, "o-", color=plt.cm.tab20(i % 20), label=label)
    ax.set_xlabel("particles n (curtains 16² … 128²)")
    ax.set_ylabel("wall time per iteration (s)\n(a direct solve: per step)")
    ax.set_title("Cost of one iteration against size; fitted time ~ n^p")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    figure.tight_layout()
    figures.save(figure, target, dpi=110)
    return 0


if __name__ == "__main__":
    figures.run(main)
