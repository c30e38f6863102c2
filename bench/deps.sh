#!/bin/sh
# deps.sh -- the Debian packages `make bench` needs beyond scripts/deps.sh's
# (which installs them the same way: dpkg check, then apt-get with
# --no-install-recommends): Mesa's EGL and OpenGL for llvmpipe, run
# surfaceless (no display server), and GNU time. `make test` does not need them.
exec "$(dirname "$0")/../scripts/deps.sh" libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri time
