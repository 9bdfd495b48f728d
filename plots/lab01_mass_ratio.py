#!/usr/bin/env python3
"""Lab 01: the share of one projection's correction taken by each end, against
the mass ratio m_i/m_j (from `lab01_single_spring --sweep-mass-ratio`)."""
from pathlib import Path

import _figures as figures
from _figures import plt

LAB = "lab01_single_spring"


def main(out_dir):
    source = Path(out_dir) / LAB / "mass_ratio_sweep.csv"
    if not source.exists():
        return figures.skip("lab01_mass_ratio", f"needs {source}; make it with: " + figures.make_command(
            LAB, f"--scene equal-masses --sweep-mass-ratio --out {source.parent}"))
    target = source.with_name("mass_ratio_share.png")
    if figures.up_to_date(target, [source]):
        return 0
    rows = figures.numeric_rows(source)
    ratio = [row["mass_ratio"] for row in rows]
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    axes.loglog(ratio, [row["expected_share_i"] for row in rows], "-", color="0.6", lw=3,
                label="analytic  w_i/(w_i+w_j) = m_j/(m_i+m_j)")
    axes.loglog(ratio, [row["share_i"] for row in rows], "o", ms=4, label="measured share of end i")
    axes.loglog(ratio, [row["share_j"] for row in rows], "s", ms=4, label="measured share of end j")
    axes.set_title("One distance projection: the lighter end moves more")
    figures.finish(axes, "mass ratio m_i / m_j", "share of the correction  |Δx| / (|Δx_i|+|Δx_j|)")
    figure.tight_layout()
    figures.save(figure, target, dpi=120)
    return 0


if __name__ == "__main__":
    figures.run(main)
