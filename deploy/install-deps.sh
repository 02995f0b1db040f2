#!/bin/sh
# Installs the Debian 12 packages umbra builds, runs and tests with.
# Idempotent: does nothing (and needs no root) when every package is present.
# Usage: deploy/install-deps.sh            (make run / make test call it)
#        deploy/install-deps.sh --no-test-tools   (no browser test tools: deploy/Dockerfile)
#        deploy/install-deps.sh --bench   (the test tools and the benchmark's: make bench)
# Test tools: Debian's chromium for the playground's browser test (tests/browser/, driven by
# puppeteer-core from npm), and nodejs/npm when no node or npm is on the PATH. Benchmark tools:
# f3d under Xvfb (xvfb, xauth) and cjpeg (libjpeg-turbo-progs) for the farm benchmark
# (tests/bench/farm_*.py): f3d brings VTK and OpenCASCADE, which `make test` does not need.
set -eu

# clang + libclang-rt-14-dev: make fuzz (libFuzzer's libclang_rt.fuzzer*.a and the sanitizer
# runtimes for Debian 12's clang 14 are in libclang-rt-14-dev, which clang does not pull in).

PKGS="build-essential pkg-config ca-certificates curl python3
libvulkan-dev vulkan-tools mesa-vulkan-drivers vulkan-validationlayers
glslang-tools libjansson-dev libmicrohttpd-dev libpng-dev zlib1g-dev
libopenexr-dev libassimp-dev libjpeg-dev libseccomp-dev libmeshoptimizer-dev libwebp-dev libavif-dev libdeflate-dev libdraco-dev xxd"
# Test tools (make test): the load balancer of the cluster test, YAML for the deploy checks,
# chromium and node for the playground's browser test, clang + libFuzzer for the fuzz targets,
# nginx (nginx-light) for the shared cache in front of the GET form (tests/http/cache.sh),
# avifdec (libavif-bin) to decode the AVIF answers the tests check.
if [ "${1:-}" != "--no-test-tools" ]; then
  PKGS="$PKGS haproxy python3-yaml chromium clang libclang-rt-14-dev nginx-light libavif-bin"
  # make bench: f3d + Xvfb (the peer renderer of the farm benchmark), cjpeg (its JPEG textures)
  [ "${1:-}" = "--bench" ] && PKGS="$PKGS f3d xvfb xauth libjpeg-turbo-progs"
  command -v node >/dev/null 2>&1 || PKGS="$PKGS nodejs"
  command -v npm >/dev/null 2>&1 || PKGS="$PKGS npm"
fi

missing=""
for p in $PKGS; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
    missing="$missing $p"
  fi
done
[ -z "$missing" ] && exit 0

echo "install-deps: installing:$missing" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: need root (or sudo) to install:$missing" >&2; exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
# A fresh machine has no package lists; refresh them once before installing.
$SUDO apt-get update -q
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends $missing
