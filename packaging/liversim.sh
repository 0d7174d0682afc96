#!/usr/bin/env bash
# The two commands of README for a new user on Debian 12:
#   packaging/liversim.sh run    install what is missing, build, start the workstation
#   packaging/liversim.sh test   install what is missing, build, run the whole test suite, then
#                                fuzz each reader briefly (the fuzz preset: docs/fuzzing.md), run
#                                the storage, bad-input and crash tests under ASan + UBSan and the
#                                threaded parts under ThreadSanitizer (docs/sanitizers.md)
# Without a display, "run" says so and runs the headless demo instead (a short simulation and a
# screenshot written to liversim-demo.png in the current directory).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
command=${1:-run}
preset=release
xvfb=(xvfb-run -a -s "-screen 0 1280x1024x24")

case "$command" in
  run | test) ;;
  *)
    echo "usage: $0 run|test" >&2
    exit 2
    ;;
esac

"$root/packaging/setup-debian.sh"
cd "$root"
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" --parallel "$(nproc)"

if [ "$command" = test ]; then
  # GUI and rendering tests need an X server: Xvfb provides one whether or not a display exists.
  "${xvfb[@]}" ctest --preset "$preset" --parallel "$(nproc)" --timeout 300
  # Then each fuzz target fuzzed briefly: a clang build of what they need, with libFuzzer and the
  # sanitizers (docs/fuzzing.md). The same build, ASan + UBSan, runs the tests of the sessions
  # store, the roles, the training centre and the CLI's recording, crash and bad-input tests.
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz --parallel "$(nproc)"
  ctest --preset fuzz --parallel "$(nproc)"
  ctest --preset asan-inputs --parallel "$(nproc)"
  # Then the threaded parts under ThreadSanitizer: the programs their tests need, and those tests
  # (the whole suites under ASan and TSan take longer than CI allows: docs/sanitizers.md).
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan --parallel "$(nproc)" --target liversim_core_tests \
    liversim_storage_tests liversim_training_centre_tests liversim_cli_record_tests liversim-cli \
    liversim_session_writer_child
  exec ctest --preset tsan-threads --parallel "$(nproc)"
fi

if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  exec "$root/build/$preset/app/liversim"
fi
demo_png="$PWD/liversim-demo.png"
echo "liversim: no display found (DISPLAY and WAYLAND_DISPLAY are unset), so the workstation"
echo "cannot open a window. Running the headless demo instead; its screenshot: $demo_png"
exec "${xvfb[@]}" "$root/build/$preset/app/liversim-cli" demo --output "$demo_png"
