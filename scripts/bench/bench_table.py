#!/usr/bin/python3
"""The README's benchmark table from bench.sh's CSV files (bench.sh writes bench.md with it).
Usage: bench_table.py CSV..."""
import csv
import sys

print("| input | run | wall s | peak MB | tets | AMIPS avg | wall / TetGen | memory / TetGen |")
print("|---|---|---:|---:|---:|---:|---:|---:|")
for path in sys.argv[1:]:
    for i, row in enumerate(csv.DictReader(open(path))):
        name = f"{row['input']} ({int(row['faces']) / 1e6:.2f}M faces)" if row["run"] == "tetgen" or i == 0 else ""
        run = "TetGen" if row["run"] == "tetgen" else f"partet K={row['pieces']}, {row['ranks']} ranks"
        print(f"| {name} | {run} | {float(row['wall_s']):.2f} | {float(row['peak_mb']):,.0f} | {int(row['tets']):,} | "
              f"{float(row['amips_avg']):.4g} | {row['wall_ratio']} | {row['mem_ratio']} |")
