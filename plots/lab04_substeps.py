#!/usr/bin/env python3
"""Lab 04, experiment 2: small steps. At a fixed cost per frame (substeps × K
sweeps), the strain and the energy for each way of splitting the work (from
`lab04_pbd --sweep-substeps ... --cost C`, substeps.csv)."""
from collections import defaultdict

import _figures as figures
from _figures import plt

LAB = "lab04_pbd"


def main(out_dir):
    source = out_dir / LAB / "substeps.csv"
    if not source.exists():
        return figures.skip("lab04_substeps", f"needs {source}; make it with: " + figures.make_command(
            LAB, "--sweep-substeps 1,2,4,8,16,32,64 --cost 64 --sweep-scenes curtain-32,rope-50 --steps 3600 "
            f"--out {source.parent}"))
    target = source.with_name("substeps.png")
    if figures.up_to_date(target, [source]):
        return 0
    from matplotlib import transforms
    runs = defaultdict(list)
    for row in figures.rows(source):
        runs[row["scene"]].append(row)
    first = next(iter(runs.values()))[0]
    cost = int(first["substeps"]) * int(first["iterations"])
    energy_time = float(first["energy_seconds"])

    figure, (left, right) = plt.subplots(1, 2, figsize=(11.5, 4.8))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    strain_top = max((figures.number(r["steady_max_strain"]) or 0.0) for rows in runs.values() for r in rows) * 2.5
    for index, (colour, (scene, rows)) in enumerate(zip(colours, runs.items())):
        ok = [r for r in rows if figures.number(r["steady_max_strain"]) is not None]
        n = [int(r["substeps"]) for r in ok]
        left.loglog(n, [figures.number(r["steady_max_strain"]) for r in ok], "o-", color=colour, label=f"{scene}: max")
        left.loglog(n, [figures.number(r["steady_rms_strain"]) for r in ok], "s--", color=colour, ms=4, mfc="white",
                    label=f"{scene}: RMS")
        with_energy = [r for r in rows if figures.number(r["energy_at_seconds"]) is not None]
        right.semilogx([int(r["substeps"]) for r in with_energy],
                       [figures.number(r["energy_at_seconds"]) - figures.number(r["energy_start"]) for r in with_energy],
                       "o-", color=colour, label=scene)
        for r in rows:
            if r["status"].startswith("diverged"):
                left.plot(int(r["substeps"]), strain_top * 1.5 ** index, "x", color=colour, ms=8, mew=2,
                          clip_on=False)
                right.plot(int(r["substeps"]), 1.0 - 0.04 * index, "x", color=colour, ms=8, mew=2, clip_on=False,
                           transform=transforms.blended_transform_factory(right.transData, right.transAxes))
    left.plot([], [], "x", color="0.4", mew=2, label="unstable (reported by the program)")
    every_n = sorted({int(r["substeps"]) for rows in runs.values() for r in rows})
    for axes in (left, right):
        axes.set_xscale("log", base=2)
        axes.set_xticks(every_n)
        axes.set_xticklabels([f"{n}\nK={cost // n}" for n in every_n])
        axes.set_xlabel(f"substeps per frame n, with K = {cost}/n sweeps each")
        axes.grid(True, which="major", alpha=0.3)
    left.set_ylabel("steady strain (mean over the last second)")
    left.set_title("Strain: smaller steps beat more iterations", fontsize=10)
    left.legend(fontsize=7.5)
    right.axhline(0.0, color="0.3", lw=0.8)
    right.set_ylabel(f"E(t = {energy_time:.3g} s) − E(0)  (J)   (× on the top edge: unstable)")
    right.set_title("Energy: hard constraints should keep it; PBD loses it", fontsize=10)
    right.legend(fontsize=8)
    figure.suptitle(f"Equal cost per frame: substeps × iterations = {cost} sweeps "
                    f"(frame Δt = {float(first['dt']):.4g} s, Gauss-Seidel)", fontsize=11)
    figure.tight_layout()
    figures.save(figure, target, dpi=120)
    return 0


if __name__ == "__main__":
    figures.run(main)
