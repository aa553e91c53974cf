#!/usr/bin/python3
"""Amdahl projection from a run's --report: the stages outside the meshing rounds (read,
validate, partition, closure, merge, seam healing, polish, check, write) are rank 0's serial
time (seam healing counted as serial, though its regions are meshed on all ranks); the meshing
rounds ("tetgen") are the parallel part, whose work is the sum of the pieces' TetGen seconds. Prints the measured split and the projected wall time on more ranks, assuming
the meshing work divides evenly and the serial stages stay as they are.
Usage: amdahl.py REPORT.json [RANKS...]   (default ranks: 16 64)"""
import json
import sys

report = json.load(open(sys.argv[1]))
ranks = [int(r) for r in sys.argv[2:]] or [16, 64]
stages = report["stage_seconds"]
parallel_stages = {"tetgen", "send", "gather"}  # send and gather are inside tetgen's time
serial = {k: v for k, v in stages.items() if k not in parallel_stages}
serial_total = sum(serial.values())
work = sum(p["tetgen_seconds"] for p in report["piece"])
measured_ranks = report["ranks"]
print(f"{report['counts']['input_faces']} faces, {measured_ranks} ranks, {report['pieces']} pieces: "
      f"total {report['total_seconds']:.1f} s")
print("serial stages (rank 0): " + ", ".join(f"{k} {v:.2f}" for k, v in serial.items()) + f"; sum {serial_total:.1f} s")
print(f"meshing rounds {stages.get('tetgen', 0):.1f} s wall, {work:.1f} s of TetGen work over the ranks")
if "serial_seconds" in report:  # measured: wall time during which no rank was meshing
    print(f"no rank meshing for {report['serial_seconds']:.1f} s (the closure after the first cap overlaps "
          f"the meshing; the projection counts all of it as serial)")
print("| ranks | projected s | serial share |")
print("|---|---|---|")
for p in [measured_ranks] + ranks:
    t = serial_total + work / p
    print(f"| {p} | {t:.1f} | {100 * serial_total / t:.0f}% |")
