"""Lab 03 figures: Jacobi against Gauss-Seidel, and Jacobi's relaxation ω.

Usage: /usr/bin/python3 plots/lab03_convergence.py OUTDIR
Reads OUTDIR/lab03_jacobi/<run>.json and <run>/convergence.csv (written by
labs/lab03_jacobi/demo.txt) and writes, next to them:
  lab03_gs_vs_jacobi.png   max strain error (log) against sweep: GS and Jacobi at several ω
  lab03_error_vs_time.png  the same against wall time
  lab03_omega.png          sweeps to the tolerance against ω, and the anchored particle
Runs that diverged end in a red cross; they are drawn, not dropped.
Exit 4 when the runs are absent.
"""
import _figures as figures
from _figures import plt

LAB = "lab03_jacobi"
SCENES = [("chain", "chain-20 (near its solution)"), ("cloth", "perturbed cloth 16x16 (lab 02)")]
FLOOR = 1e-17  # an error of exactly 0 is drawn here on the log axis


def load(lab_dir, prefix):
    """Runs named <prefix>-gs, <prefix>-omega-W and (anchored) <prefix>-summed, sorted by ω."""
    runs = []
    paths = [lab_dir / f"{prefix}-gs.json", lab_dir / f"{prefix}-summed.json",
             *lab_dir.glob(f"{prefix}-omega-*.json")]
    for summary_path in paths:
        if not summary_path.is_file():
            continue
        table_path = lab_dir / summary_path.stem / "convergence.csv"
        if not table_path.is_file():
            continue
        runs.append((figures.summary(summary_path), figures.columns(table_path)))
    runs.sort(key=lambda run: (run[0]["method"] != "gauss-seidel", run[0].get("averaging") == "none",
                               run[0].get("omega", 0.0)))
    return runs


def label(summary):
    if summary["method"] == "gauss-seidel":
        name = "Gauss-Seidel"
    elif summary.get("averaging") == "none":
        name = "summed Jacobi, no averaging"
    else:
        name = f"Jacobi, omega = {summary['omega']:g}"
    if summary["diverged"]:
        return f"{name}: diverged at sweep {summary['diverged_at_sweep']}"
    if summary.get("sweeps_to_tolerance") is not None:
        return f"{name}: {summary['tolerance']:.0e} at sweep {summary['sweeps_to_tolerance']}"
    return f"{name}: {summary['outcome']}"


def style(summary, index, count):
    if summary["method"] == "gauss-seidel":
        return {"color": "black", "linewidth": 2.0}
    if summary.get("averaging") == "none":
        return {"color": "tab:gray", "linestyle": "--"}
    return {"color": plt.cm.viridis(index / max(count - 1, 1))}


def draw(axis, runs, x_key, x_scale):
    jacobi = [run for run in runs if run[0]["method"] != "gauss-seidel"]
    for summary, table in runs:
        index = jacobi.index((summary, table)) if summary["method"] != "gauss-seidel" else 0
        x = [value * x_scale for value in table[x_key]]
        y = [max(value, FLOOR) for value in table["max_strain_error"]]
        axis.semilogy(x, y, label=label(summary), **style(summary, index, len(jacobi)))
        if summary["diverged"]:
            axis.semilogy([x[-1]], [y[-1]], "x", color="red", markersize=10, markeredgewidth=2)
    if runs:
        axis.axhline(runs[0][0]["tolerance"], color="0.6", linestyle=":", linewidth=1)
    axis.set_ylabel("max strain error |l - L| / L (1)")
    axis.grid(True, which="major", alpha=0.3)
    axis.legend(fontsize=7)


def comparison_figure(lab_dir, x_key, x_label, x_scale, path):
    figure, axes = plt.subplots(1, len(SCENES), figsize=(6 * len(SCENES), 4.5), squeeze=False)
    for axis, (prefix, title) in zip(axes[0], SCENES):
        draw(axis, load(lab_dir, prefix), x_key, x_scale)
        axis.set_title(title)
        axis.set_xlabel(x_label)
    figure.suptitle("Lab 03: Gauss-Seidel against averaged Jacobi (dotted: tolerance, red x: diverged)")
    figure.tight_layout()
    figures.save(figure, path, dpi=120)


def omega_figure(lab_dir, path):
    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    chain = load(lab_dir, "chain")
    jacobi = [summary for summary, _ in chain if summary["method"] == "jacobi"]
    top = max([s["sweeps"] for s in jacobi] + [1])
    for summary in jacobi:
        omega = summary["omega"]
        if summary.get("sweeps_to_tolerance") is not None:
            left.bar(omega, summary["sweeps_to_tolerance"], width=0.08, color="tab:blue")
        else:
            color = "red" if summary["diverged"] else "tab:gray"
            left.bar(omega, top, width=0.08, color=color, alpha=0.35)
            text = f"diverged\nat sweep {summary['diverged_at_sweep']}" if summary["diverged"] else "not\nconverged"
            left.text(omega, top * 0.5, text, ha="center", va="center", fontsize=7, rotation=90)
    for summary, _ in chain:
        if summary["method"] == "gauss-seidel" and summary.get("sweeps_to_tolerance") is not None:
            left.axhline(summary["sweeps_to_tolerance"], color="black", linestyle="--",
                         label=f"Gauss-Seidel: {summary['sweeps_to_tolerance']} sweeps")
    left.set_xlabel("relaxation omega (1)")
    left.set_ylabel(f"sweeps to max strain error <= {jacobi[0]['tolerance']:.0e}" if jacobi else "sweeps")
    left.set_title("chain-20: averaged Jacobi against omega")
    left.grid(True, axis="y", alpha=0.3)
    left.legend(fontsize=8)
    draw(right, load(lab_dir, "anchored"), "sweep", 1.0)
    right.set_xlabel("sweep")
    right.set_title("anchored particle: (1 - omega) delta per sweep")
    figure.suptitle("Lab 03: the relaxation factor omega (0 is drawn at 1e-17)")
    figure.tight_layout()
    figures.save(figure, path, dpi=120)


def main(out_dir):
    lab_dir = out_dir / LAB
    if not any(load(lab_dir, prefix) for prefix, _ in SCENES):
        return figures.skip("lab03_convergence", f"needs {lab_dir}/chain-gs.json and chain-gs/convergence.csv (and "
                            f"the other chain-*/cloth-* runs of labs/lab03_jacobi/demo.txt); make them with: "
                            f"./course demo lab03 --out {out_dir}")
    sources = [path for summary in lab_dir.glob("*.json") for path in (summary, summary.with_suffix("") / "convergence.csv")]
    for target, draw in ((lab_dir / "lab03_gs_vs_jacobi.png",
                          lambda path: comparison_figure(lab_dir, "sweep", "sweep", 1.0, path)),
                         (lab_dir / "lab03_error_vs_time.png",
                          lambda path: comparison_figure(lab_dir, "total_seconds", "wall time of the sweeps (ms)",
                                                         1e3, path)),
                         (lab_dir / "lab03_omega.png", lambda path: omega_figure(lab_dir, path))):
        if not figures.up_to_date(target, sources):
            draw(target)
    return 0


if __name__ == "__main__":
    figures.run(main)
