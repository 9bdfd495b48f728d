#!/usr/bin/env python3
"""Lab 07, experiment 2: what each method buys per millisecond on the 20-link
hard chain. Mean (over 300 frames) of the max strain |phi|/L against the
median wall time per 1/60 s frame, log-log: PBD (lab 04, Gauss-Seidel) with
K = 1 ... 256 sweeps and with n substeps of one sweep, and this lab's Schur and
KKT steps (with and without the post-step projection) with n substeps.

Reads OUTDIR/lab07_constrained_dynamics/compare.csv, writes compare.png beside it."""
import _figures as figures
from _figures import plt

LAB = "lab07_constrained_dynamics"
MAKE = ("./course demo lab07   (or: ./course run lab07 --scene ragdoll-chain-20 --compare-pbd 1,2,4,8,16,32,64,128,256 "
        "--compare-substeps 1,2,4,8,16,32 --out OUT/lab07_constrained_dynamics)")


def main(out_dir):
    source = out_dir / LAB / "compare.csv"
    if not source.is_file():
        return figures.skip("lab07_compare", f"{source}: missing; make it with {MAKE}")
    target = source.parent / "compare.png"
    if figures.up_to_date(target, [source]):
        return 0
    rows = figures.rows(source, ok_only=True)
    series = {}
    for r in rows:
        if r["method"].startswith("pbd"):
            key = "PBD, K sweeps, 1 step" if r["substeps"] == "1" else "PBD, n substeps × 1 sweep"
            tag = f"K={r['iterations']}" if r["substeps"] == "1" else f"n={r['substeps']}"
        else:
            key = {"schur": "Schur, n substeps", "kkt": "KKT, n substeps",
                   "schur-stabilized": "Schur + projection, n substeps"}[r["method"]]
            tag = f"n={r['substeps']}"
        series.setdefault(key, []).append((float(r["median_ms_per_frame"]), float(r["mean_max_strain"]), tag))
    # PBD with one sweep and one step belongs to both PBD curves.
    first = [p for p in series.get("PBD, K sweeps, 1 step", []) if p[2] == "K=1"]
    if first and "PBD, n substeps × 1 sweep" in series:
        series["PBD, n substeps × 1 sweep"].insert(0, (first[0][0], first[0][1], "n=1"))
    styles = {"PBD, K sweeps, 1 step": "o-", "PBD, n substeps × 1 sweep": "s--", "Schur, n substeps": "^-",
              "KKT, n substeps": "v:", "Schur + projection, n substeps": "D-"}
    figure, axes = plt.subplots(figsize=(8.5, 5.5))
    for key, points in series.items():
        points.sort()
        axes.loglog([p[0] for p in points], [max(p[1], 1e-17) for p in points], styles.get(key, "o-"),
                    label=key, ms=4)
        for x, y, tag in (points[0], points[-1]):
            axes.annotate(tag, (x, max(y, 1e-17)), fontsize=7, xytext=(3, 3), textcoords="offset points")
    scene = rows[0]["scene"] if rows else "?"
    axes.set_xlabel("median wall time per 1/60 s frame (ms)")
    axes.set_ylabel("mean over frames of max strain |φ| / L")
    axes.set_title(f"{scene}: constraint error against cost")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figures.save(figure, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
