#!/usr/bin/env python3
"""Lab 01: the share of one projection's correction taken by each end, against
the mass ratio m_i/m_j (from `lab01_single_spring --sweep-mass-ratio`)."""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LAB = "lab01_single_spring"


def read_rows(path):
    with open(path, newline="") as handle:
        return [{key: float(value) for key, value in row.items()} for row in csv.DictReader(handle)]


def main(out_dir):
    source = Path(out_dir) / LAB / "mass_ratio_sweep.csv"
    if not source.exists():
        print(f"lab01_mass_ratio: needs {source}; make it with: ./course run lab01_solution "
              f"--scene equal-masses --sweep-mass-ratio --out {source.parent}")
        return 4
    rows = read_rows(source)
    ratio = [row["mass_ratio"] for row in rows]
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    axes.loglog(ratio, [row["expected_share_i"] for row in rows], "-", color="0.6", lw=3,
                label="analytic  w_i/(w_i+w_j) = m_j/(m_i+m_j)")
    axes.loglog(ratio, [row["share_i"] for row in rows], "o", ms=4, label="measured share of end i")
    axes.loglog(ratio, [row["share_j"] for row in rows], "s", ms=4, label="measured share of end j")
    axes.set_xlabel("mass ratio m_i / m_j")
    axes.set_ylabel("share of the correction  |Δx| / (|Δx_i|+|Δx_j|)")
    axes.set_title("One distance projection: the lighter end moves more")
    axes.grid(True, which="major", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    target = source.with_name("mass_ratio_share.png")
    figure.savefig(target, dpi=120)
    print(f"wrote {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out"))
