#!/usr/bin/python3
"""Amdahl projection from a run's --report: the stages outside the meshing rounds (read,
validate, partition, closure, merge, seam healing, polish, check, write) are rank 0's serial
time (seam healing counted as serial, though its regions are meshed on all ranks); the meshing
rounds ("tetgen") are the parallel part, whose work is the sum of the pieces' TetGen seconds.
The caps are triangulated on every rank (reports with per-rank "cap_seconds"): their work is
divided by the ranks too, and only the rest of the closure stage (rank 0 placing the caps,
closing the pieces, waiting for a cap) stays serial. Prints the measured split and the projected
wall time on more ranks, assuming the work divides evenly and the rest stays as it is.
Usage: amdahl.py REPORT.json [RANKS...]   (default ranks: 16 64)"""
import json
import sys

report = json.load(open(sys.argv[1]))
ranks = [int(r) for r in sys.argv[2:]] or [16, 64]
stages = report["stage_seconds"]
parallel_stages = {"tetgen", "send", "gather"}  # send and gather are inside tetgen's time
serial = {k: v for k, v in stages.items() if k not in parallel_stages}
work = sum(p["tetgen_seconds"] for p in report["piece"])
cap_work = sum(r.get("cap_seconds", 0) for r in report["rank"])
if cap_work > 0:  # the caps rank 0 built itself come out of its closure stage
    serial["closure"] = max(serial.get("closure", 0) - report["rank"][0]["cap_seconds"], 0)
serial_total = sum(serial.values())
measured_ranks = report["ranks"]
print(f"{report['counts']['input_faces']} faces, {measured_ranks} ranks, {report['pieces']} pieces: "
      f"total {report['total_seconds']:.1f} s")
print("serial stages (rank 0): " + ", ".join(f"{k} {v:.2f}" for k, v in serial.items()) + f"; sum {serial_total:.1f} s")
print(f"meshing rounds {stages.get('tetgen', 0):.1f} s wall, {work:.1f} s of TetGen work over the ranks")
region_work = sum(r.get("region_seconds", 0) for r in report["rank"])
if region_work > 0:
    print(f"seam and polish regions: {region_work:.2f} s of TetGen work over the ranks (inside the seam healing and "
          f"polish stages, which the projection counts as serial)")
if cap_work > 0:
    print(f"caps: {cap_work:.2f} s of triangulation over the ranks (" +
          ", ".join(f"rank {r['rank']} {r['cap_seconds']:.2f} s / {r['caps']:.0f}" for r in report["rank"]) +
          "); the closure above is rank 0's rest")
if "serial_seconds" in report:  # measured: wall time during which no rank was meshing
    print(f"no rank meshing for {report['serial_seconds']:.1f} s (most of the closure overlaps the meshing; "
          f"the projection counts rank 0's part of it as serial)")
print("| ranks | projected s | serial share |")
print("|---|---|---|")
for p in [measured_ranks] + ranks:
    t = serial_total + (work + cap_work) / p
    print(f"| {p} | {t:.1f} | {100 * serial_total / t:.0f}% |")
