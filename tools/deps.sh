#!/bin/sh
# tools/deps.sh: install the Debian packages libmech needs, only those missing.
# Runs apt-get as root, or through sudo when not root.
set -e
# Extra packages may be named as arguments (make test-slurm: slurm-wlm munge).
PKGS="make gcc libc6-dev pkg-config libyaml-dev libsuitesparse-dev libsundials-dev libhdf5-dev libgsl-dev libcriterion-dev python3-dev python3-numpy python3-pytest parallel libcminpack-dev libnlopt-dev $*"
missing=""
for p in $PKGS; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
if [ -z "$missing" ]; then
    echo "deps: all present ($PKGS)"
    exit 0
fi
if [ "$(id -u)" -eq 0 ]; then SUDO=""; elif command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "deps: missing:$missing; run as root: apt-get install -y$missing" >&2
    exit 1
fi
echo "deps: installing missing Debian packages:$missing"
echo "deps: apt-get update"
$SUDO apt-get update -qq
echo "deps: apt-get install -y$missing"
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
echo "deps: done"
