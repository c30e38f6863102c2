#!/bin/sh
# deps.sh -- the Debian packages `make bench` needs beyond scripts/deps.sh's:
# Mesa's EGL and OpenGL (llvmpipe, run surfaceless) and GNU time for peak
# memory. Checked with dpkg first; installed with apt-get (sudo when not root).
set -u
PACKAGES="libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri time"

missing=""
for p in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0

echo "bench deps: installing:$missing" >&2
if [ "$(id -u)" -eq 0 ]; then
    SUDO=""
elif command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
else
    echo "bench deps: error: not root and no sudo; install as root: apt-get install --no-install-recommends$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
if ! $SUDO apt-get update -qq >&2 || ! $SUDO apt-get install -y -qq --no-install-recommends $missing >&2; then
    echo "bench deps: error: apt-get could not install:$missing" >&2
    exit 1
fi
