#!/usr/bin/env bash
# The Debian package: `cpack -G DEB` in BUILD_DIR, its dependencies (from dpkg-shlibdeps), then
# installed with apt (which brings what it depends on), `partet --version`, the man page and the
# pkg-config file from it, and removed again. Needs root (CI).
# Usage: deb.sh BUILD_DIR
set -euo pipefail
build=$(realpath "$1")
(cd "$build" && cpack -G DEB > cpack.log) || { cat "$build/cpack.log"; exit 1; }
deb=$(ls "$build"/partet_*.deb)
dpkg-deb -I "$deb" | grep -E "Package|Version|Depends"
export DEBIAN_FRONTEND=noninteractive
apt-get install -y -qq "$deb" > /dev/null
trap 'apt-get purge -y -qq partet > /dev/null' EXIT
[ "$(command -v partet)" = /usr/bin/partet ] || { echo "FAIL: partet is not /usr/bin/partet"; exit 1; }
/usr/bin/partet --version
[ -f /usr/share/man/man1/partet.1 ] || [ -f /usr/share/man/man1/partet.1.gz ] || { echo "FAIL: no man page"; exit 1; }
pkg-config --modversion partet
echo "deb: $(basename "$deb") installs; partet --version runs from it"
