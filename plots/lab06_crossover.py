"""Lab 06 figure and table: time to a relative objective error, PD against Newton, per size.

Usage: /usr/bin/python3 plots/lab06_crossover.py OUTDIR
Reads OUTDIR/lab06_projective_dynamics/crossover.csv (the --convergence line of
labs/lab06_projective_dynamics/demo.txt) and writes next to it:
  crossover.png   seconds to reach (g - g*)/g* = 1e-2, 1e-3, 1e-6 against the number of
                  unknowns, one panel per target, log-log; PD with and without its factorization
  crossover.md    the same numbers as a table, with iterations and factorizations
Exit 4 when the data are absent.
"""

import _figures as figures
from _figures import plt

LAB = "lab06_projective_dynamics"
COMMAND = figures.make_command(LAB, "--convergence --sweep-scenes pd-curtain-16,pd-curtain-32,pd-curtain-64,"
                               "pd-curtain-128 --out out/lab06_projective_dynamics (or ./course demo)")


def figure(rows, path):
    from matplotlib import transforms
    from matplotlib.lines import Line2D
    targets = sorted({float(row["target"]) for row in rows}, reverse=True)
    plot, axes = plt.subplots(1, len(targets), figsize=(5 * len(targets), 4.5), squeeze=False)
    for axis, target in zip(axes[0], targets):
        missing = []
        for method, color, marker in (("pd", "tab:blue", "s"), ("newton", "tab:red", "o")):
            chosen = [row for row in rows if row["method"] == method and float(row["target"]) == target]
            reached = [row for row in chosen if row["reached"] == "yes"]
            sizes = [int(row["unknowns"]) for row in reached]
            axis.loglog(sizes, [float(row["seconds"]) for row in reached], marker=marker, color=color,
                        label=f"{method}" + (" (with its factorization)" if method == "pd" else ""))
            if method == "pd":
                axis.loglog(sizes, [max(float(row["seconds_without_setup"]), 1e-7) for row in reached],
                            marker=marker, color=color, linestyle=":", fillstyle="none",
                            label="pd, factorization amortised")
            missing.extend((row, color) for row in chosen if row["reached"] != "yes")
        # Runs that did not get there: a marker on the top edge, above the data
        # (inside the panel, labels covered the points and the legend, issue 25).
        edge = transforms.blended_transform_factory(axis.transData, axis.transAxes)
        for row, color in missing:  # side by side where both methods miss at one size
            axis.plot(int(row["unknowns"]) * (0.93 if row["method"] == "pd" else 1.07), 1.0, marker="x" if row["reached"] == "no" else "$?$", ls="",
                      color=color, ms=9, mew=2, clip_on=False, transform=edge)
        axis.set_title(f"(g - g*)/g* <= {target:g}", pad=12)
        figures.finish(axis, "unknowns (movable particles)", "wall time of the step (s)", legend=None)
    handles, labels = axes[0][0].get_legend_handles_labels()
    handles += [Line2D([], [], color="0.3", marker="x", mew=2, ls=""),
                Line2D([], [], color="0.3", marker="$?$", ms=9, ls="")]
    labels += ["not reached (on the top edge)", "undecided (on the top edge)"]
    plot.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8, frameon=False)
    plot.suptitle("Lab 06: time to an accuracy, one step of the curtains")
    plot.tight_layout(rect=(0, 0.07, 1, 1))
    figures.save(plot, path, dpi=120)


def table(rows, path):
    lines = ["| scene | unknowns | target | PD: iterations, s (s without the factorization) | "
             "Newton: iterations = factorizations, s |", "|---|---:|---:|---|---|"]
    keys = sorted({(int(row["unknowns"]), row["scene"], float(row["target"])) for row in rows},
                  key=lambda key: (key[0], -key[2]))
    for unknowns, scene, target in keys:
        cells = {}
        for row in rows:
            if row["scene"] == scene and float(row["target"]) == target:
                if row["reached"] != "yes":
                    cells[row["method"]] = row["reached"].replace("no", "not reached")
                elif row["method"] == "pd":
                    cells["pd"] = (f"{row['iterations']}, {float(row['seconds']):.3g} "
                                   f"({float(row['seconds_without_setup']):.3g})")
                else:
                    cells["newton"] = f"{row['iterations']}, {float(row['seconds']):.3g}"
        lines.append(f"| {scene} | {unknowns} | {target:g} | {cells.get('pd', '-')} | {cells.get('newton', '-')} |")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def main(out_dir):
    source = out_dir / LAB / "crossover.csv"
    if not source.is_file():
        return figures.skip("lab06_crossover", f"{source} is missing; make it with {COMMAND}")
    if not figures.up_to_date([source.parent / "crossover.png", source.parent / "crossover.md"], [source]):
        rows = figures.rows(source)
        figure(rows, source.parent / "crossover.png")
        table(rows, source.parent / "crossover.md")
    wrinkled = source.parent / "wrinkled" / "crossover.csv"
    if wrinkled.is_file() and not figures.up_to_date(wrinkled.parent / "crossover.md", [wrinkled]):
        table(figures.rows(wrinkled), wrinkled.parent / "crossover.md")
    return 0


if __name__ == "__main__":
    figures.run(main)
