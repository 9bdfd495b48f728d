"""Lab 02 figures: Gauss-Seidel convergence for each spring order.

Usage: /usr/bin/python3 plots/lab02_orders.py OUTDIR
Reads OUTDIR/lab02_gauss_seidel/<scene>-<order>.json and <scene>-<order>/*.csv
(written by labs/lab02_gauss_seidel/demo.txt) and writes, next to them:
  lab02_orders.png            max strain error (log) against sweep, per order
  lab02_error_vs_time.png     max strain error (log) against wall time
  lab02_order_difference.png  how far apart the final states of two orders are
Exit 4 when the runs are absent.
"""
import _figures as figures
from _figures import plt

LAB = "lab02_gauss_seidel"
SCENES = [("chain", "perturbed chain (20 links)"),
          ("cloth", "perturbed cloth 16x16, structural"),
          ("cloth-shear", "perturbed cloth 16x16, + shear, bending")]
ORDERS = [("forward", "tab:blue"), ("reverse", "tab:orange"), ("random", "tab:green")]
FLOOR = 1e-17  # an error of exactly 0 is drawn here on the log axis


def load_runs(lab_dir):
    runs = {}
    for prefix, _ in SCENES:
        for order, _ in ORDERS:
            name = f"{prefix}-{order}"
            summary, table = lab_dir / f"{name}.json", lab_dir / name / "convergence.csv"
            if summary.is_file() and table.is_file():
                runs[name] = (figures.summary(summary), figures.columns(table))
    return runs


def floor(values):
    return [max(value, FLOOR) for value in values]


def convergence_figure(runs, x_key, x_label, x_scale, path):
    figure, axes = plt.subplots(1, len(SCENES), figsize=(5 * len(SCENES), 4), squeeze=False)
    for axis, (prefix, title) in zip(axes[0], SCENES):
        for order, color in ORDERS:
            run = runs.get(f"{prefix}-{order}")
            if not run:
                continue
            summary, table = run
            x = [value * x_scale for value in table[x_key]]
            reached = summary.get("sweeps_to_tolerance")
            label = f"{order}: " + (f"1e-10 at sweep {reached}" if reached is not None else summary["outcome"])
            axis.semilogy(x, floor(table["max_strain_error"]), color=color, label=label)
            axis.axhline(summary["tolerance"], color="0.6", linestyle=":", linewidth=1)
        axis.set_title(title)
        axis.set_xlabel(x_label)
        axis.set_ylabel("max strain error |l - L| / L (1)")
        axis.grid(True, which="major", alpha=0.3)
        axis.legend(fontsize=8)
    figure.suptitle("Lab 02: Gauss-Seidel, one curve per spring order (dotted: tolerance)")
    figure.tight_layout()
    figures.save(figure, path, dpi=120)


def difference_figure(lab_dir, runs, path):
    figure, axes = plt.subplots(1, 2, figsize=(11, 4))
    for axis, prefix in zip(axes, ["chain", "cloth"]):
        name = f"{prefix}-forward"
        positions = lab_dir / name / "positions.csv"
        if name not in runs or not positions.is_file():
            axis.set_visible(False)
            continue
        summary, _ = runs[name]
        table = figures.columns(positions)
        if "x_compare" not in table:
            axis.set_visible(False)
            continue
        distance = [((a - b) ** 2 + (c - d) ** 2 + (e - f) ** 2) ** 0.5
                    for a, b, c, d, e, f in zip(table["x"], table["x_compare"], table["y"], table["y_compare"],
                                                table["z"], table["z_compare"])]
        axis.semilogy(table["particle"], floor(distance), "o-", markersize=3, color="tab:purple",
                      label="|x_forward - x_reverse| per particle")
        compare = summary["compare"]
        axis.axhline(summary["max_strain_error"], color="tab:blue", linestyle="--",
                     label=f"max strain error, forward: {summary['max_strain_error']:.1e}")
        axis.axhline(compare["max_strain_error"], color="tab:orange", linestyle=":",
                     label=f"max strain error, reverse: {compare['max_strain_error']:.1e}")
        axis.set_title(f"{summary['scene']}: final states after {summary['iterations']} sweeps")
        axis.set_xlabel("particle index")
        axis.set_ylabel("distance (m) / strain error (1)")
        axis.grid(True, alpha=0.3)
        axis.legend(fontsize=8)
    figure.suptitle("Both orders satisfy every spring to round-off, at different positions (0 is drawn at 1e-17)")
    figure.tight_layout()
    figures.save(figure, path, dpi=120)


def main(out_dir):
    lab_dir = out_dir / LAB
    runs = load_runs(lab_dir)
    if not runs:
        return figures.skip("lab02_orders", f"needs {lab_dir}/chain-forward.json and chain-forward/convergence.csv "
                            f"(and the other order runs of labs/lab02_gauss_seidel/demo.txt); make them with: "
                            f"./course demo lab02 --out {out_dir}")
    sources = [path for name in runs for path in (lab_dir / f"{name}.json", *(lab_dir / name).glob("*.csv"))]
    for target, draw in ((lab_dir / "lab02_orders.png",
                          lambda path: convergence_figure(runs, "sweep", "sweep", 1.0, path)),
                         (lab_dir / "lab02_error_vs_time.png",
                          lambda path: convergence_figure(runs, "total_seconds", "wall time of the sweeps (ms)",
                                                          1e3, path)),
                         (lab_dir / "lab02_order_difference.png", lambda path: difference_figure(lab_dir, runs, path))):
        if not figures.up_to_date(target, sources):
            draw(target)
    return 0


if __name__ == "__main__":
    figures.run(main)
