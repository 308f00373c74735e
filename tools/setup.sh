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
  libcpp-httplib-dev      # the web server of `sedbridge view` (src/view/view_server.h)
  chromium                # headless page tests of `sedbridge view` (tests/view/)
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

# The view's page libraries (three.js, uPlot), pinned by tools/view-web/package-lock.json;
# the build copies them next to the page. Nothing is fetched when the view runs.
install_view_web() {
  local dir
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/view-web"
  if [ -d "$dir/node_modules/three" ] && [ -d "$dir/node_modules/uplot" ]; then return 0; fi
  # npm only when there is none: a nodejs from elsewhere that bundles npm conflicts with Debian's.
  if ! command -v npm >/dev/null 2>&1; then
    echo "setup: installing npm"
    $SUDO apt-get install -y -qq --no-install-recommends npm
  fi
  echo "setup: npm ci in $dir"
  (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
}

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  install_view_web
  exit 0
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_view_web
echo "setup: done"
