#!/bin/sh
# deps.sh -- install the Debian packages shadowlab builds, tests and plots with.
# Checks with dpkg first, so a machine that has them all installs nothing.
# Uses sudo when not root; fails with a clear message when it cannot install.
set -u
PACKAGES="build-essential pkg-config liblua5.4-dev lua5.4 libembree-dev libopenexr-dev \
libopenimageio-dev zlib1g-dev gnuplot-nox glmark2-data \
chromium parallel clang libclang-rt-14-dev valgrind"
# Other package sets (bench/deps.sh) pass their own list as arguments.
[ $# -gt 0 ] && PACKAGES="$*"

missing=""
for p in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0

echo "deps: installing:$missing" >&2
if [ "$(id -u)" -eq 0 ]; then
    SUDO=""
elif command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
else
    echo "deps: error: not root and no sudo; install as root: apt-get install --no-install-recommends$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
if ! $SUDO apt-get update -qq >&2 || ! $SUDO apt-get install -y -qq --no-install-recommends $missing >&2; then
    echo "deps: error: apt-get could not install:$missing" >&2
    echo "deps: check the network to the Debian mirror, or install them by hand" >&2
    exit 1
fi
