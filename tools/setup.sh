#!/usr/bin/env bash
# Installs every Debian package sedbridge needs. Idempotent and non-interactive;
# run as root (or with sudo available) on Debian 12. Skips apt entirely when all
# packages are already present, so repeated runs cost a second.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git
  libeigen3-dev libyaml-cpp-dev
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev
  libssl-dev              # OpenSSL libcrypto: HMAC-SHA256 of DISPLAY_COMMAND (display/command_authenticator.h)
  libomp-dev
  libsuitesparse-dev      # CHOLMOD supernodal Cholesky (fem/cholmod_solver.h); pulls in METIS for nested dissection
  libopenblas-dev         # threaded BLAS for CHOLMOD's dense supernode kernels
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  clang libclang-rt-dev
  libgmsh-dev gmsh
  calculix-ccx
  python3 python3-matplotlib python3-numpy
  python3-distributed     # Dask distributed: tools/study.py's local cluster, dask-scheduler, dask-worker
  default-jdk-headless libjchart2d-java xvfb xdotool
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"
