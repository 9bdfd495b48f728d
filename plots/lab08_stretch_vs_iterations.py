#!/usr/bin/env python3
"""Lab 08, the experiment: the hanging chain's steady stretch against the
iteration count K, PBD and XPBD on the same chain (from `lab08_xpbd
--sweep-iterations ... --method pbd|xpbd`, stretch_vs_iterations_<method>.csv).

Left: the steady total stretch, with the material's (the chain at rest with
its springs' stiffness) as a dashed line. Right: the stiffness the chain
shows relative to its material's, k_eff/k = material stretch / steady stretch.
Filled markers: the run settled; hollow: it had not when it stopped; a cross
on the top edge: the program reported it unstable. Also writes the table of
the handout as stretch_vs_iterations.md."""
import _figures as figures
from _figures import plt

LAB = "lab08_xpbd"
METHODS = ("pbd", "xpbd")
COMMAND = figures.make_command(LAB, "--sweep-iterations 1,2,4,8,16,32,64,128,256,512,1024 "
                               "--method {method} --steps 3600 --out {out}")


def draw(axes, runs, column, label):
    values = [figures.number(r[column]) for rows in runs.values() for r in rows if figures.number(r[column])]
    top = max(values) * 3.0
    styles = {"pbd": ("C0", "PBD (lab 04: every spring a hard constraint)"),
              "xpbd": ("C3", "XPBD (compliance 1/k)")}
    for index, (method, rows) in enumerate(runs.items()):
        colour, name = styles[method]
        k = [int(r["iterations"]) for r in rows if figures.number(r[column])]
        y = [figures.number(r[column]) for r in rows if figures.number(r[column])]
        axes.loglog(k, y, "-", color=colour, label=name)
        for r in rows:
            value = figures.number(r[column])
            if value is None and r["status"].startswith("diverged"):
                axes.plot(int(r["iterations"]), top * 1.6 ** index, "x", color=colour, ms=8, mew=2, clip_on=False)
            elif value:
                axes.plot(int(r["iterations"]), value, "o", color=colour, ms=5,
                          mfc=colour if r["status"] == "settled" else "white")
    every_k = sorted({int(r["iterations"]) for rows in runs.values() for r in rows})
    axes.set_xscale("log", base=2)
    axes.set_xticks(every_k)
    axes.set_xticklabels([str(k) for k in every_k])
    axes.set_xlabel("iterations per step K (Gauss-Seidel sweeps)")
    axes.set_ylabel(label)
    axes.grid(True, which="major", alpha=0.3)


def main(out_dir):
    lab_dir = out_dir / LAB
    sources = [lab_dir / f"stretch_vs_iterations_{method}.csv" for method in METHODS]
    for method, source in zip(METHODS, sources):
        if not source.exists():
            return figures.skip("lab08_stretch_vs_iterations", f"needs {source}; make it with: "
                                + COMMAND.format(method=method, out=lab_dir))
    target, table = lab_dir / "stretch_vs_iterations.png", lab_dir / "stretch_vs_iterations.md"
    if figures.up_to_date([target, table], sources):
        return 0
    runs = {method: figures.rows(source) for method, source in zip(METHODS, sources)}
    first = runs["xpbd"][0]
    material = figures.number(first["material_total_stretch"])
    figure, (left, right) = plt.subplots(1, 2, figsize=(11.5, 5.0))
    draw(left, runs, "steady_total_stretch", "steady total stretch (m)")
    if material:
        left.axhline(material, color="k", ls="--", lw=1, label=f"the material's: {material:.4g} m")
    draw(right, runs, "stiffness_ratio", "apparent stiffness k_eff / k")
    right.axhline(1.0, color="k", ls="--", lw=1, label="k_eff = k")
    for axes in (left, right):
        axes.plot([], [], "o", color="0.4", label="settled")
        axes.plot([], [], "o", color="0.4", mfc="white", label="not settled (stopped at the time limit)")
        axes.plot([], [], "x", color="0.4", mew=2, label="unstable (reported by the program)")
    left.legend(fontsize=8, loc="lower left")
    right.legend(fontsize=8, loc="upper left")
    left.set_title("Steady stretch of the hanging chain", fontsize=10)
    right.set_title("Stiffness it shows, relative to its springs'", fontsize=10)
    figure.suptitle(f"{first['scene']}: PBD's stiffness moves with K, XPBD's converges to the material's "
                    f"(Δt = {float(first['dt']):.4g} s, {first['substeps']} substep)", fontsize=11)
    figure.tight_layout()
    figures.save(figure, target, dpi=120)
    figures.write_table(table, markdown_table(runs))
    return 0


def markdown_table(runs):
    """Steady total stretch (k_eff/k in brackets) per K, PBD and XPBD, for the handout."""
    every_k = sorted({int(r["iterations"]) for rows in runs.values() for r in rows})
    lines = ["| K | " + " | ".join(f"{m.upper()} stretch (k_eff/k)" for m in runs) + " |",
             "|---:|" + "---:|" * len(runs)]
    for k in every_k:
        cells = []
        for rows in runs.values():
            row = next((r for r in rows if int(r["iterations"]) == k), None)
            if row is None:
                cells.append("")
            elif row["status"].startswith("diverged"):
                cells.append("unstable")
            else:
                ratio = figures.number(row["stiffness_ratio"])
                cell = f"{float(row['steady_total_stretch']):.4g} m"
                if ratio:
                    cell += f" ({ratio:.3g})"
                cells.append(cell + ("" if row["status"] == "settled" else " not settled"))
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    figures.run(main)
