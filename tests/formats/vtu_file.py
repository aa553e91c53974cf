#!/usr/bin/python3
"""Reads and writes the .vtu files partet writes (raw appended arrays, zlib blocks with UInt64
headers), so that a test can damage one array and write the file back as partet would.
  arrays, head = read(path)     # arrays: name -> numpy array (flat), in the file's order
  write(path, arrays, head)     # the head's offsets are made again; a dropped array is left out
As a command: vtu_file.py PATH 'PYTHON' runs the statements on `a` (the arrays) and writes PATH back.
"""
import re
import sys
import zlib

import numpy as np

TYPES = {"Float64": np.float64, "Int64": np.int64, "Int32": np.int32, "UInt8": np.uint8}
MARKER = '<AppendedData encoding="raw">\n_'


def read(path):
    data = open(path, "rb").read()
    base = data.index(MARKER.encode()) + len(MARKER)
    head = data[:base].decode()
    arrays = {}
    for tag in re.findall(r"<DataArray [^>]*>", head):
        name = re.search(r'Name="([^"]*)"', tag).group(1)
        kind = TYPES[re.search(r'type="([^"]*)"', tag).group(1)]
        at = base + int(re.search(r'offset="([0-9]*)"', tag).group(1))
        blocks = int(np.frombuffer(data, np.uint64, 1, at)[0])
        sizes = np.frombuffer(data, np.uint64, 3 + blocks, at)[3:]
        at += 8 * (3 + blocks)
        raw = b""
        for size in sizes:
            raw += zlib.decompress(data[at:at + int(size)])
            at += int(size)
        arrays[name] = np.frombuffer(raw, kind).copy()
    return arrays, head


def write(path, arrays, head):
    block = 1 << 20
    packed = {}
    for name, values in arrays.items():
        raw = values.tobytes()
        pieces = [zlib.compress(raw[i:i + block]) for i in range(0, len(raw), block)]
        last = len(raw) - (len(pieces) - 1) * block if pieces else 0
        header = np.array([len(pieces), block, last] + [len(p) for p in pieces], np.uint64).tobytes()
        packed[name] = header + b"".join(pieces)
    offset = 0
    for tag in re.findall(r"<DataArray [^>]*>\n", head):
        name = re.search(r'Name="([^"]*)"', tag).group(1)
        if name not in packed:
            head = head.replace(tag, "")
            continue
        head = head.replace(tag, re.sub(r'offset="[0-9]*"', f'offset="{offset}"', tag))
        offset += len(packed[name])
    head = re.sub(r"<PointData[^>]*>\n</PointData>\n", "", head)
    with open(path, "wb") as out:
        out.write(head.encode())
        for name in arrays:
            out.write(packed[name])
        out.write(b"\n</AppendedData>\n</VTKFile>\n")


if __name__ == "__main__":
    a, head = read(sys.argv[1])
    exec(sys.argv[2])
    write(sys.argv[1], a, head)
