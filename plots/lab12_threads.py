"""Lab 12 figure: the VBD sweep's time on 1 and 2 threads, and the colours.

Usage: /usr/bin/python3 plots/lab12_threads.py OUTDIR
Reads OUTDIR/lab12_vertex_block_descent/exp3/threads-N.json (the exp3 lines of
labs/lab12_vertex_block_descent/demo.txt) and writes threads.png and
threads.md (the table) in OUTDIR/lab12_vertex_block_descent/, beside the
lab's other figures. The title says what these runs measured, not what they
should: the speed-up of their times per sweep, and whether their final
positions agree to the bit. Exit 4 when the runs are absent.
"""
import _figures as figures
from _figures import plt

LAB = "lab12_vertex_block_descent"


def same_bits(runs):
    """True when every run ended at the same positions (the summaries' 17 digits round-trip)."""
    positions = [run.get("positions") for run in runs]
    return all(p is not None and p == positions[0] for p in positions)


def title(runs, per_sweep):
    first = runs[0]
    text = f"Lab 12: VBD sweep on {first['scene']}, {first['colours']} colours"
    if len(runs) > 1:
        speedup = per_sweep[0] / per_sweep[-1]
        text += f"; {runs[-1]['threads']} threads: {speedup:.2f}x the speed of {runs[0]['threads']}"
        text += ("; the same final positions, bit for bit" if same_bits(runs)
                 else "; the final positions DIFFER between thread counts")
    return text


def main(out_dir):
    lab_dir = out_dir / LAB
    run_dir = lab_dir / "exp3"
    sources = sorted(run_dir.glob("threads-*.json")) if run_dir.is_dir() else []
    runs = [figures.summary(path) for path in sources]
    runs = [run for run in runs if run.get("iterations_done")]
    if not runs:
        return figures.skip("lab12_threads", f"needs {run_dir}/threads-1.json (and threads-2); make them with: " +
                            figures.make_command(LAB, f"--scene pd-curtain-64 --method vbd --iterations 50 --steps 5 "
                                                 f"--threads 1 --summary {run_dir}/threads-1.json (then --threads 2)"))
    target, table = lab_dir / "threads.png", lab_dir / "threads.md"
    if figures.up_to_date([target, table], sources):
        return 0
    runs.sort(key=lambda run: run["threads"])
    per_sweep = [1e3 * run["seconds"] / run["iterations_done"] for run in runs]
    names = [f"{run['threads']} thread(s)" for run in runs]
    figure, axis = plt.subplots(figsize=(7, 4))
    axis.bar(names, per_sweep, color=["tab:blue", "tab:orange", "tab:green", "tab:red"][: len(runs)])
    for k, value in enumerate(per_sweep):
        axis.annotate(f"{value:.3g} ms", (k, value), ha="center", va="bottom", fontsize=9)
    figures.finish(axis, "OpenMP threads", "wall time per sweep (ms), one run each", legend=None)
    axis.set_title(title(runs, per_sweep), fontsize=8)
    figure.tight_layout()
    figures.save(figure, target)
    lines = ["| threads | sweeps | seconds | ms per sweep | speed-up | colours | same final positions as 1 thread |",
             "|---|---|---|---|---|---|---|"]
    for run, value in zip(runs, per_sweep):
        same = "yes" if run.get("positions") == runs[0].get("positions") else "no"
        lines.append(f"| {run['threads']} | {run['iterations_done']} | {run['seconds']:.3g} | {value:.3g} | "
                     f"{per_sweep[0] / value:.2f} | {run['colours']} | {same} |")
    figures.write_table(table, "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    figures.run(main)
