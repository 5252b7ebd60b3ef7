#!/usr/bin/env bash
# Installs the Debian 12 packages that the build needs; with --tests also what the tests and the
# deployment checks use (Prometheus + promtool, Python gRPC, docker-compose, Node for the
# Kubernetes schema check); with --bench the peer odometries nidevo-bench compares against
# (OpenCV-contrib's rgbd module, Open3D). Idempotent and non-interactive; quick when everything
# is present. With --fuzz: clang and its sanitizer runtimes (libFuzzer, ThreadSanitizer).
# Usage: setup.sh [--tests] [--bench] [--fuzz]
set -euo pipefail
cd "$(dirname "$0")/.."

tests=0
bench=0
fuzz=0
for arg in "$@"; do
  case "$arg" in
    --tests) tests=1 ;;
    --bench) bench=1 ;;
    --fuzz) fuzz=1 ;;
    *) echo "setup.sh: unknown option '$arg' (--tests, --bench, --fuzz)" >&2; exit 2 ;;
  esac
done

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libfftw3-dev libabsl-dev
  # The minimal OpenCV set: libopencv-dev would pull ~1.5 GB of contrib, VTK and Qt.
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  # The service: gRPC's CMake config checks for the plugins in protobuf-compiler-grpc.
  libgrpc++-dev libgrpc-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  prometheus-cpp-dev libcurl4-openssl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
)
if [ $bench -eq 1 ]; then
  packages+=(libopencv-contrib-dev libopen3d-dev)
fi
if [ $fuzz -eq 1 ]; then
  # clang-14 only recommends its runtimes, and --no-install-recommends skips them.
  packages+=(clang libclang-rt-14-dev)
fi
if [ $tests -eq 1 ]; then
  packages+=(prometheus python3-grpcio python3-grpc-tools docker-compose yamllint curl clang-format)
  # kubectl renders the kustomize manifests; Debian's (1.20) does if none is installed.
  command -v kubectl >/dev/null || packages+=(kubernetes-client)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ $tests -eq 1 ] && [ -f deploy/validate/package.json ]; then
  command -v npm >/dev/null || { echo "setup: the Kubernetes check needs Node.js and npm" >&2; exit 1; }
  # The Kubernetes schema check's npm packages, pinned by the lock file, kept out of the tree.
  if [ ! -d build/npm/node_modules/kubernetes-models ]; then
    mkdir -p build/npm
    cp deploy/validate/package.json deploy/validate/package-lock.json build/npm/
    (cd build/npm && npm ci --no-audit --no-fund --loglevel=error)
  fi
fi
