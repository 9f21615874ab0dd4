#!/usr/bin/env bash
# Scalespace quick start. One command each (see README.md):
#   ./build.sh demo   install what is missing, build, run `scalespace curvature` on a generated sample
#   ./build.sh test   install what is missing, build, run the whole test suite
#                     (Release build, then an AddressSanitizer + UBSan build, then a format check)
#   ./build.sh build  install what is missing and build (Release) only
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-demo}
jobs=$(nproc)

scripts/setup.sh

configure_and_build() {  # dir, extra cmake args...
  local dir=$1
  shift
  cmake -S . -B "$dir" -G Ninja "$@" >/dev/null
  cmake --build "$dir" -j "$jobs"
}

case "$mode" in
  build)
    configure_and_build build -DCMAKE_BUILD_TYPE=Release
    ;;
  demo)
    configure_and_build build -DCMAKE_BUILD_TYPE=Release -DSCALESPACE_TESTS=OFF -DSCALESPACE_BENCH=OFF
    mkdir -p out
    ./build/scalespace generate torus -n 200000 --noise 0.0001 --seed 1 -o out/sample_torus.ply
    ./build/scalespace info out/sample_torus.ply
    ./build/scalespace curvature out/sample_torus.ply -o out/sample_torus_curvature.ply --scale-k 80
    echo "demo: result written to $(pwd)/out/sample_torus_curvature.ply (summary: out/sample_torus_curvature.json)"
    ;;
  test)
    configure_and_build build -DCMAKE_BUILD_TYPE=Release -DSCALESPACE_WERROR=ON
    ctest --test-dir build --output-on-failure -j "$jobs" --timeout 300
    # Sanitizers: same tests, ASan + UBSan, optimised enough to stay quick; benches not built.
    configure_and_build build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSCALESPACE_SANITIZE=ON \
      -DSCALESPACE_BENCH=OFF
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
      ctest --test-dir build-asan --output-on-failure -j "$jobs" --timeout 600
    scripts/check_format.sh
    echo "test: all tests passed (Release and ASan+UBSan), formatting clean"
    ;;
  *)
    echo "usage: $0 [demo|test|build]" >&2
    exit 2
    ;;
esac
