#!/bin/sh
# Installs the build dependencies (Debian 12 packages; needs root or sudo when
# something is missing) and builds everything in build/ (Release).
#   ./setup.sh            install what is missing, configure, build
#   ./setup.sh --debug    same, Debug with address/undefined sanitizers in build-debug/
# MPS_WERROR=ON makes compiler warnings errors (CI sets it).
# MPS_FUZZ=1 also installs the optional clang + libFuzzer runtime (Debian's
# clang, libclang-rt-dev): ctest then builds and runs the fuzz targets
# (label fuzz; docs/security.md), which report as skipped without it.
set -eu
cd "$(dirname "$0")"

PKGS="build-essential cmake pkg-config libzmq3-dev libhdf5-dev libsuitesparse-dev \
libopenblas-dev libyaml-dev python3 python3-numpy python3-zmq python3-h5py python3-matplotlib \
python3-yaml procps"
# libzmq3-dev pulls in Debian's libzmq5, built with libsodium: CURVE, which
# coupling over tcp requires (proto/PROTOCOL.md section 10), is checked below.
if [ "${MPS_FUZZ:-0}" = "1" ]; then
    PKGS="$PKGS clang libclang-rt-dev"
fi

missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
    echo "setup: installing$missing"
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
fi

# ZeroMQ's CURVE security (needs a libzmq built with libsodium, as Debian's is)
if /usr/bin/python3 -c "import ctypes, sys; sys.exit(0 if ctypes.CDLL('libzmq.so.5').zmq_has(b'curve') == 1 else 1)"; then
    echo "setup: libzmq has CURVE (libsodium): coupling over tcp is authenticated"
else
    echo "setup: warning: this libzmq has no CURVE: coupling.transport=tcp will be refused (ipc works)"
fi

if [ "${1:-}" = "--debug" ]; then
    cmake -S . -B build-debug -DCMAKE_BUILD_TYPE=Debug -DMPS_SANITIZE=ON \
        -DMPS_WERROR="${MPS_WERROR:-OFF}"
    cmake --build build-debug -j"$(nproc)"
else
    cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DMPS_WERROR="${MPS_WERROR:-OFF}"
    cmake --build build -j"$(nproc)"
fi
