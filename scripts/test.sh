#!/usr/bin/env bash
# Install what is missing, build everything, and run the whole test suite (unit + integration).
# Run as root on Debian 12. CI runs exactly this (.ci/run).
#
#   scripts/test.sh                      the normal build (build/) and the whole suite
#   scripts/test.sh --sanitize [ARGS]    the same suite built with AddressSanitizer and UndefinedBehaviorSanitizer
#                                        (gcc, -O1 -g) into build-sanitize/; any finding fails its test (halt on
#                                        error, leaks included). ARGS go to ctest (e.g. -E 'pipeline_' or -L unit).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${1:-}" != "--sanitize" ]]; then
  bash scripts/setup.sh
  ctest --test-dir build --output-on-failure --timeout 900 -j"${ADIT_JOBS:-2}"
  exit 0
fi
shift
bash scripts/setup.sh --no-build
BUILD=build-sanitize
# -fno-sanitize=vptr: gcc's vptr check breaks LCM 1.3.1's own C++ subscription callbacks (lcm-cpp-impl.hpp:
# cb_func): a ten-line program that only subscribes through lcm::LCM reports "invalid vptr" there and then
# crashes, and runs clean under every other check; with it, every test that starts a stage process failed.
SAN="-fsanitize=address,undefined -fno-sanitize=vptr -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
# ADIT_TEST_TIME_SCALE: test timeouts x4 and the simulated world of the live tests at a quarter of real time
# (CMakeLists.txt, tests/integration/time_scale.sh): the sanitized stages run 3-5x slower than the normal build's.
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DADIT_STRICT=ON -DADIT_TEST_TIME_SCALE=4 \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_CXX_FLAGS="$SAN" -DCMAKE_C_FLAGS="$SAN" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null
nice -n "${ADIT_NICE:-0}" cmake --build "$BUILD" -j"${ADIT_JOBS:-2}"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
ctest --test-dir "$BUILD" --output-on-failure -j"${ADIT_JOBS:-2}" "$@"
