#!/usr/bin/env bash
# partet as a package: `cmake --install` into a fresh prefix, then a consumer found through
# find_package(partet) (and one built with pkg-config) against that prefix only, run in one
# process and under MPIEXEC -n 2.
# Usage: consumer.sh BUILD_DIR MPIEXEC
set -euo pipefail
build=$(realpath "$1")
mpiexec=$2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
for f in bin/partet include/partet/partet.hpp lib/pkgconfig/partet.pc lib/cmake/partet/partetConfig.cmake \
         share/man/man1/partet.1; do
  [ -e "$work/prefix/$f" ] || { echo "FAIL: not installed: $f"; exit 1; }
done
# Only the public API is installed.
[ "$(ls "$work/prefix/include/partet")" = "$(printf 'errors.hpp\nmesh_types.hpp\npartet.hpp')" ] ||
  { echo "FAIL: installed headers: $(ls "$work/prefix/include/partet" | tr '\n' ' ')"; exit 1; }
"$work/prefix/bin/partet" --version
cmake -S "$here/consumer" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log" ||
  { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" > "$work/build.log" || { cat "$work/build.log"; exit 1; }
cd "$work"
./consumer/mesh_torus
$mpiexec -n 2 ./consumer/mesh_torus
# The same program through pkg-config.
PKG_CONFIG_PATH="$work/prefix/lib/pkgconfig" c++ "$here/consumer/mesh_torus.cpp" -o mesh_torus_pc \
  $(PKG_CONFIG_PATH="$work/prefix/lib/pkgconfig" pkg-config --cflags --libs partet)
LD_LIBRARY_PATH="$work/prefix/lib" ./mesh_torus_pc
echo "consumer: built against the installed package and ran in 1 and 2 ranks"
