#!/bin/sh
# Installs the peers `colophony bench precision` measures beside Colophony: STK (the
# `stk::Bowed` instrument, libstk-dev), Faust (physmodels.lib's violin, the faust package)
# and g++ to build their small drivers. Debian packages; needs root and the package
# registry. Does nothing for what is already installed.
set -eu
missing=""
dpkg -s libstk-dev >/dev/null 2>&1 || missing="$missing libstk-dev"
command -v faust >/dev/null 2>&1 || missing="$missing faust"
command -v g++ >/dev/null 2>&1 || missing="$missing g++"
if [ -z "$missing" ]; then
    echo "peers: libstk-dev, faust and g++ already installed"
    exit 0
fi
echo "peers: installing$missing"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
# shellcheck disable=SC2086 # word splitting of the package list is intended
apt-get install -y -q --no-install-recommends $missing
