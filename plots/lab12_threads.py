"""Lab 12 figure: the VBD sweep's time on 1 and 2 threads, and the colours.

Usage: /usr/bin/python3 plots/lab12_threads.py OUTDIR
Reads OUTDIR/lab12_vertex_block_descent/exp3/threads-N.json (the exp3 lines of
labs/lab12_vertex_block_descent/demo.txt) and writes exp3/threads.png and
exp3/threads.md (the table) beside them. Exit 4 when the runs are absent.
"""
import _figures as figures
from _figures import plt

LAB = "lab12_vertex_block_descent"


def main(out_dir):
    run_dir = out_dir / LAB / "exp3"
    sources = sorted(run_dir.glob("threads-*.json")) if run_dir.is_dir() else []
    runs = [figures.summary(path) for path in sources]
    runs = [run for run in runs if run.get("iterations_done")]
    if not runs:
        return figures.skip("lab12_threads", f"needs {run_dir}/threads-1.json (and threads-2); make them with: " +
                            figures.make_command(LAB, f"--scene pd-curtain-64 --method vbd --iterations 50 --steps 5 "
                                                 f"--threads 1 --summary {run_dir}/threads-1.json (then --threads 2)"))
    target = run_dir / "threads.png"
    if figures.up_to_date([target, run_dir / "threads.md"], sources):
        return 0
    runs.sort(key=lambda run: run["threads"])
    per_sweep = [1e3 * run["seconds"] / run["iterations_done"] for run in runs]
    names = [f"{run['threads']} thread(s)" for run in runs]
    figure, axis = plt.subplots(figsize=(6, 4))
    axis.bar(names, per_sweep, color=["tab:blue", "tab:orange", "tab:green", "tab:red"][: len(runs)])
    for k, value in enumerate(per_sweep):
        axis.annotate(f"{value:.3g} ms", (k, value), ha="center", va="bottom", fontsize=9)
    figures.finish(axis, "OpenMP threads", "wall time per sweep (ms)", legend=None)
    first = runs[0]
    axis.set_title(f"Lab 12: VBD sweep on {first['scene']}, {first['colours']} colours "
                   f"(same bits on every thread count)", fontsize=9)
    figure.tight_layout()
    figures.save(figure, target)
    lines = ["| threads | sweeps | seconds | ms per sweep | speed-up | colours |", "|---|---|---|---|---|---|"]
    for run, value in zip(runs, per_sweep):
        lines.append(f"| {run['threads']} | {run['iterations_done']} | {run['seconds']:.3g} | {value:.3g} | "
                     f"{per_sweep[0] / value:.2f} | {run['colours']} |")
    figures.write_table(run_dir / "threads.md", "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    figures.run(main)
