"""Lab 03 figure: time per Jacobi sweep on 1 and 2 threads.

Usage: /usr/bin/python3 plots/lab03_threads.py OUTDIR
Reads OUTDIR/lab03_jacobi/threads-N.json and threads-N/convergence.csv
(labs/lab03_jacobi/demo.txt) and writes lab03_threads.png next to them.
Exit 4 when the runs are absent.
"""
import statistics

import _figures as figures
from _figures import plt

LAB = "lab03_jacobi"


def main(out_dir):
    lab_dir = out_dir / LAB
    runs, sources = [], []
    for summary_path in lab_dir.glob("threads-*.json"):
        table_path = lab_dir / summary_path.stem / "convergence.csv"
        if table_path.is_file():
            seconds = [float(row["sweep_seconds"]) for row in figures.rows(table_path) if int(row["sweep"]) > 0]
            if seconds:
                runs.append((figures.summary(summary_path), seconds))
                sources += [summary_path, table_path]
    if not runs:
        return figures.skip("lab03_threads", f"needs {lab_dir}/threads-1.json and threads-1/convergence.csv (and "
                            "threads-2); make them with: " + figures.make_command(
                                LAB, f"--scene cloth-128 --threads 1 --iterations 200 --out {lab_dir}/threads-1 "
                                f"--summary {lab_dir}/threads-1.json (then --threads 2)"))
    target = lab_dir / "lab03_threads.png"
    if figures.up_to_date(target, sources):
        return 0
    runs.sort(key=lambda run: run[0]["threads"])

    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    medians = []
    for summary, seconds in runs:
        left.plot(range(1, len(seconds) + 1), [s * 1e3 for s in seconds], linewidth=0.8,
                  label=f"{summary['threads']} thread(s)")
        medians.append(statistics.median(seconds))
    left.set_xlabel("sweep")
    left.set_ylabel("wall time of the sweep (ms)")
    left.set_ylim(bottom=0)
    left.grid(True, alpha=0.3)
    left.legend()
    left.set_title(f"{runs[0][0]['scene']}: {runs[0][0]['springs']} springs, "
                   f"{runs[0][0]['projections_per_sweep']:.0f} projections per sweep")

    labels = [str(summary["threads"]) for summary, _ in runs]
    bars = right.bar(labels, [m * 1e3 for m in medians], color="tab:blue")
    for bar, median, (summary, _) in zip(bars, medians, runs):
        rate = summary["projections_per_sweep"] / median
        right.text(bar.get_x() + bar.get_width() / 2, bar.get_height(),
                   f"{median * 1e3:.3g} ms\n{rate / 1e6:.0f} M proj/s\nx{medians[0] / median:.2f}",
                   ha="center", va="bottom", fontsize=8)
    right.set_xlabel("OpenMP threads")
    right.set_ylabel("median time per sweep (ms)")
    right.set_ylim(0, max(medians) * 1e3 * 1.35)
    right.set_title("median over the sweeps, speed-up against 1 thread")
    figure.suptitle("Lab 03: time per Jacobi sweep (the positions agree bit for bit)")
    figure.tight_layout()
    figures.save(figure, target, dpi=120)
    return 0


if __name__ == "__main__":
    figures.run(main)
