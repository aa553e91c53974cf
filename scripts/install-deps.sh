#!/usr/bin/env bash
# Installs the Debian 12 packages partet needs to build, test and benchmark.
# Idempotent: packages already present are skipped; apt runs only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libcgal-dev libgmp-dev libmpfr-dev   # exact predicates, 2D CDT, surface checks and IO
  libtet1.5-dev tetgen                 # TetGen library (piece meshing) and binary (benchmarks)
  libeigen3-dev                        # PCA of the input vertices
  libopenmpi-dev openmpi-bin           # MPI layer
  libboost-serialization-dev           # piece and result messages
  libcli11-dev                         # command line
  nlohmann-json3-dev                   # --report FILE.json
  zlib1g-dev                           # compressed .vtu output
  libhdf5-openmpi-dev                  # XDMF output: one HDF5 file all ranks write at once
  python3-meshio python3-h5py gmsh      # tests: independent readers of the mesh formats
  python3-vtk9                         # tests: VTK itself (ParaView's reader) reads the .pvtu set
  python3-dolfinx                      # tests: a FEM code reads the XDMF output in parallel
  python3-matplotlib                   # scripts/render.py pictures and the benchmark plots
  libgtest-dev                         # unit tests
  time python3                         # GNU time and JSON parsing for the benchmark scripts
  e2fsprogs                            # tests: an ext4 disk (a loop mount) that fills up
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
