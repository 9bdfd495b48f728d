"""Lab 14 figures (experiment 1): a cloth draped over a sphere, per method and mu.

Usage: /usr/bin/python3 plots/lab14_drape.py OUTDIR
Reads every OUTDIR/lab14_contact/**/drape.csv (--drape, README.md's
experiment 1) and writes beside it:
  drape.png           per method and mu: the worst penetration, the time per
                      step, the time to rest and the final kinetic + potential
                      energy
and every OUTDIR/lab14_contact/drape-*/per_step.csv (the demo's drape runs),
writing beside each:
  drape_history.png   contacts found and active (sticking, sliding) and the kinetic energy per step
Exit 4 when neither is there.
"""
import _figures as figures
from _figures import plt
from matplotlib.patches import Patch

LAB = "lab14_contact"
METHODS = ["pbd", "xpbd", "constrained"]
FLOOR = 1e-18  # a penetration of exactly 0 is drawn here (and the panel says so)
KINETIC_FLOOR = 1e-12  # J: the history's kinetic energy below this (frame 0's 0) is drawn here


def draw_table(table, target):
    found = figures.rows(table)
    frictions = sorted({float(r["friction"]) for r in found})
    panels = [("max_penetration", "worst penetration (m)", True), ("seconds_per_step", "wall time per step (s)", True),
              ("rest_time", "time to rest (s; –: never)", False),
              ("energy_end", "final kinetic + potential energy (J)", False)]
    figure, axes = plt.subplots(1, len(panels), figsize=(4.0 * len(panels), 3.8))
    width = 0.8 / max(len(frictions), 1)
    for axis, (key, label, log) in zip(axes, panels):
        drawn, floored = 0, False
        for f, mu in enumerate(frictions):
            xs, ys = [], []
            for m, method in enumerate(METHODS):
                for r in found:
                    if r["method"] != method or float(r["friction"]) != mu:
                        continue
                    x = m + (f - (len(frictions) - 1) / 2) * width
                    if r[key] == "":  # never at rest: say so where the bar would be
                        axis.text(x, 0.0, "–", ha="center", va="bottom", color=f"C{f}", fontsize=14)
                        continue
                    value = float(r[key])
                    floored = floored or (log and value < FLOOR)
                    xs.append(x)
                    ys.append(max(value, FLOOR) if log else value)
            # One colour per μ, the same in every panel (the bar cycle skips a μ with no bars).
            axis.bar(xs, ys, width=width, label=f"μ = {mu:g}", color=f"C{f}")
            drawn += len(xs)
        if log and floored:
            axis.annotate(f"an exact 0 is drawn at {FLOOR:g}", (0.02, 0.02), xycoords="axes fraction", fontsize=7)
        if drawn == 0:
            axis.annotate("no run came to rest (–)", (0.5, 0.5), xycoords="axes fraction", ha="center", fontsize=8)
            axis.set_ylim(0.0, 1.0)
        axis.set_xticks(range(len(METHODS)))
        axis.set_xticklabels(METHODS)
        axis.set_xlim(-0.5, len(METHODS) - 0.5)
        if log:
            axis.set_yscale("log")
        figures.finish(axis, "method", label, legend=None)
        if drawn:  # handles of their own: a μ without a bar in this panel still has its colour
            axis.legend(handles=[Patch(color=f"C{f}", label=f"μ = {mu:g}") for f, mu in enumerate(frictions)],
                        fontsize=7)
    figure.suptitle("Lab 14, experiment 1: the drape (32² cloth over a sphere above a floor)")
    figure.tight_layout()
    figures.save(figure, target, dpi=110)


def draw_history(per_step, target):
    found = figures.rows(per_step, ok_only=True)
    # A per_step.csv of an earlier release has one "contacts" column (the ones found).
    counts = ("contacts_found", "contacts_active") if found and "contacts_found" in found[0] else ("contacts",)
    data = {key: figures.column(found, key) for key in ("time", *counts, "sticking", "sliding", "kinetic")}
    figure, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6))
    for key in (*counts, "sticking", "sliding"):
        left.plot(data["time"], data[key], label=key.replace("contacts_", ""))
    figures.finish(left, "time (s)", "contacts per step (1)")
    right.semilogy(data["time"], [max(k, KINETIC_FLOOR) for k in data["kinetic"]])
    if any(k < KINETIC_FLOOR for k in data["kinetic"]):
        right.annotate(f"below {KINETIC_FLOOR:g} J (frame 0: 0) drawn at {KINETIC_FLOOR:g}", (0.02, 0.02),
                       xycoords="axes fraction", fontsize=7)
    figures.finish(right, "time (s)", "kinetic energy (J)", legend=None)
    figure.suptitle(f"Lab 14: {per_step.parent.name}")
    figure.tight_layout()
    figures.save(figure, target, dpi=110)


def main(out_dir):
    lab_dir = out_dir / LAB
    tables = sorted(lab_dir.rglob("drape.csv")) if lab_dir.is_dir() else []
    histories = sorted(lab_dir.glob("drape-*/per_step.csv")) if lab_dir.is_dir() else []
    if not tables and not histories:
        return figures.skip("lab14_drape", f"no drape.csv or drape-*/per_step.csv under {lab_dir}; make one with " +
                            figures.make_command(LAB, f"--drape --out {lab_dir}/exp1") + " (or ./course demo lab14)")
    for table in tables:
        target = table.with_name("drape.png")
        if not figures.up_to_date(target, [table]):
            draw_table(table, target)
    for per_step in histories:
        target = per_step.with_name("drape_history.png")
        if not figures.up_to_date(target, [per_step]):
            draw_history(per_step, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
