"""Lab 06 figures: one step's convergence, projective dynamics against Newton.

Usage: /usr/bin/python3 plots/lab06_convergence.py OUTDIR
Reads OUTDIR/lab06_projective_dynamics/convergence.csv (and wrinkled/convergence.csv
when present), written by the --convergence lines of labs/lab06_projective_dynamics/demo.txt,
and writes next to each CSV, per scene:
  convergence_<scene>.png   relative objective error (g - g*)/g* against iteration (left)
                            and against wall time (right), log scales
Exit 4 when the data are absent.
"""
import _figures as figures
from _figures import plt

LAB = "lab06_projective_dynamics"
COMMAND = figures.make_command(LAB, "--convergence --sweep-scenes pd-curtain-16,pd-curtain-32,pd-curtain-64,"
                               "pd-curtain-128 --out out/lab06_projective_dynamics (or ./course demo lab06)")
FLOOR = 1e-17  # an error of exactly 0 (the reference itself) is drawn here
STYLE = {"pd": {"color": "tab:blue", "label": "projective dynamics (1 factorization)"},
         "newton": {"color": "tab:red", "marker": "o", "markersize": 3,
                    "label": "Newton (1 factorization per iteration)"}}
TARGETS = (1e-2, 1e-3, 1e-6)


def read_runs(path):
    """{scene: {method: [rows]}} from a convergence.csv."""
    runs = {}
    for row in figures.rows(path):
        runs.setdefault(row["scene"], {}).setdefault(row["method"], []).append(row)
    return runs


def draw(scene, methods, path):
    figure, (by_iteration, by_time) = plt.subplots(1, 2, figsize=(12, 4.5))
    for method, rows in methods.items():
        error = [max(float(row["relative_error"]), FLOOR) for row in rows]
        iteration = [int(row["iteration"]) for row in rows]
        seconds = [float(row["seconds"]) for row in rows]
        style = STYLE.get(method, {"label": method})
        by_iteration.loglog([max(i, 0.8) for i in iteration], error, **style)
        by_time.loglog(seconds, error, **style)
        if method == "pd":
            # Without the one factorization: the cost once it is amortised over a scene.
            setup = float(rows[0]["setup_seconds"])
            by_time.loglog([s - setup for s in seconds[1:]], error[1:], color="tab:blue", linestyle=":",
                           label="projective dynamics, factorization not counted")
    for axis in (by_iteration, by_time):
        for target in TARGETS:
            axis.axhline(target, color="0.6", linestyle=":", linewidth=1)
        axis.set_ylabel("relative objective error (g - g*) / g* (1)")
        axis.grid(True, which="major", alpha=0.3)
    by_iteration.set_xlabel("iteration (iteration 0 drawn at 0.8)")
    by_time.set_xlabel("wall time of the step (s)")
    by_iteration.legend(fontsize=8)
    by_time.legend(fontsize=8)
    first = next(iter(methods.values()))[0]
    note = "" if first["reference_converged"] == "1" else \
        f" (g* known to about {float(first['reference_last_decrease']):.0e})"
    figure.suptitle(f"Lab 06: one implicit-Euler step of {scene}, {first['unknowns']} unknowns{note}; "
                    f"zero error drawn at {FLOOR:g}")
    figure.tight_layout()
    figures.save(figure, path, dpi=120)


def main(out_dir):
    lab_dir = out_dir / LAB
    tables = [path for path in (lab_dir / "convergence.csv", lab_dir / "wrinkled" / "convergence.csv")
              if path.is_file()]
    if not tables:
        return figures.skip("lab06_convergence", f"{lab_dir / 'convergence.csv'} is missing; make it with {COMMAND}")
    for table in tables:
        for scene, methods in read_runs(table).items():
            target = table.parent / f"convergence_{scene}.png"
            if not figures.up_to_date(target, [table]):
                draw(scene, methods, target)
    return 0


if __name__ == "__main__":
    figures.run(main)
