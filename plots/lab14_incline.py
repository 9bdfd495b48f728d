"""Lab 14 figure (experiment 2): the incline's stick/slip boundary against mu.

Usage: /usr/bin/python3 plots/lab14_incline.py OUTDIR
Reads every OUTDIR/lab14_contact/**/incline.csv (the --incline line of
labs/lab14_contact/demo.txt) and writes beside it:
  incline.png   the acceleration down the slope after 100 steps against the
                angle, one panel per mu, every method (markers) over Coulomb's
                g (sin theta - mu cos theta) (line), atan mu marked
Exit 4 when the data are absent.
"""
import math

import _figures as figures
from _figures import plt

LAB = "lab14_contact"
MARKERS = {"pbd": "o", "xpbd": "x", "constrained": "+"}


def draw(table, target):
    found = figures.rows(table)
    frictions = sorted({float(r["friction"]) for r in found})
    figure, axes = plt.subplots(1, len(frictions), figsize=(4.2 * len(frictions), 3.8), squeeze=False)
    for axis, mu in zip(axes[0], frictions):
        rows = [r for r in found if float(r["friction"]) == mu]
        angles = sorted({float(r["angle_deg"]) for r in rows})
        fine = [angles[0] + (angles[-1] - angles[0]) * k / 200 for k in range(201)]
        coulomb = [max(0.0, 9.81 * (math.sin(math.radians(a)) - mu * math.cos(math.radians(a)))) for a in fine]
        axis.plot(fine, coulomb, "-", color="0.6", linewidth=1, label="Coulomb: g (sin θ − μ cos θ)")
        for method, marker in MARKERS.items():
            mine = [r for r in rows if r["method"] == method]
            if mine:
                axis.plot(figures.column(mine, "angle_deg"), figures.column(mine, "acceleration"), marker,
                          linestyle="none", label=method)
        axis.axvline(math.degrees(math.atan(mu)), color="0.3", linestyle=":", linewidth=1, label="atan μ")
        figures.finish(axis, "incline angle θ (degrees)", "acceleration down the slope (m/s²)", legend=7)
        axis.set_title(f"μ = {mu:g}")
    figure.suptitle("Lab 14: a particle on an incline, 100 steps of 1/60 s (stuck: 0)")
    figure.tight_layout()
    figures.save(figure, target, dpi=110)


def main(out_dir):
    lab_dir = out_dir / LAB
    tables = sorted(lab_dir.rglob("incline.csv")) if lab_dir.is_dir() else []
    if not tables:
        return figures.skip("lab14_incline", f"no incline.csv under {lab_dir}; make one with " +
                            figures.make_command(LAB, f"--incline --out {lab_dir}/exp2") + " (or ./course demo lab14)")
    for table in tables:
        target = table.with_name("incline.png")
        if not figures.up_to_date(target, [table]):
            draw(table, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
