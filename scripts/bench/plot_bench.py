#!/usr/bin/python3
"""Plots scripts/bench/bench.sh's CSV: wall time and peak memory against the piece count, one line per
input, each relative to TetGen on the same input (dashed line at 1) when TetGen was run.
Usage: plot_bench.py BENCH.csv OUT.png   (needs python3-matplotlib)"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, png_path):
    rows = list(csv.DictReader(open(csv_path)))
    series = defaultdict(list)
    for r in rows:
        if r["run"] == "partet":
            series[r["input"]].append(r)
    relative = all(r["wall_ratio"] for rs in series.values() for r in rs)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, rs in sorted(series.items()):
        rs.sort(key=lambda r: int(r["pieces"]))
        ks = [int(r["pieces"]) for r in rs]
        label = f"{name} ({int(rs[0]['faces']):,} faces)"
        if relative:
            axes[0].plot(ks, [float(r["wall_ratio"]) for r in rs], "o-", label=label)
            axes[1].plot(ks, [float(r["mem_ratio"]) for r in rs], "o-", label=label)
        else:
            axes[0].plot(ks, [float(r["wall_s"]) for r in rs], "o-", label=label)
            axes[1].plot(ks, [float(r["peak_mb"]) for r in rs], "o-", label=label)
    ranks = rows[-1]["ranks"] if rows else "?"
    for ax, what in zip(axes, ["wall time", "peak memory (largest process)"]):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("pieces K")
        ax.set_ylabel(f"{what} / TetGen" if relative else what)
        if relative:
            ax.axhline(1.0, color="grey", linestyle="--", linewidth=1)
            ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
    axes[0].set_title(f"partet on {ranks} ranks vs tetgen -pYQ")
    axes[1].set_title("memory")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
