#!/usr/bin/env bash
# The two commands of README for a new user on Debian 12:
#   packaging/liversim.sh run    install what is missing, build, start the workstation
#   packaging/liversim.sh test   install what is missing, build with warnings as errors, run the
#                                whole test suite, then fuzz each reader briefly (the fuzz preset:
#                                docs/fuzzing.md), run the storage, bad-input and crash tests under
#                                ASan + UBSan and the threaded parts under ThreadSanitizer
#                                (docs/sanitizers.md); docs/ci.md says what each step costs
# Without a display, "run" says so and runs the headless demo instead (a short simulation and a
# screenshot written to liversim-demo.png in the current directory).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
command=${1:-run}
preset=release
# -noreset: otherwise the server resets whenever its last client leaves, and a test connecting
# then is refused ("could not connect to display" in one CI run, two GUI tests in parallel).
xvfb=(xvfb-run -a -s "-screen 0 1280x1024x24 -noreset")

case "$command" in
  run | test) ;;
  *)
    echo "usage: $0 run|test" >&2
    exit 2
    ;;
esac

# ccache (installed by setup-debian.sh) keys objects on paths relative to the checkout, so a new
# clone on this machine compiles only what changed since any earlier build (docs/ci.md).
export CCACHE_BASEDIR="$root"

# A step's wall time, for docs/ci.md: "liversim: step NAME took S s".
step_started=0
begin_step() {
  step_name=$1
  step_started=$(date +%s)
}
end_step() {
  echo "liversim: step $step_name took $(($(date +%s) - step_started)) s"
}

begin_step setup
"$root/packaging/setup-debian.sh"
end_step
cd "$root"
warnings=(-DLIVERSIM_WARNINGS_AS_ERRORS=OFF)
if [ "$command" = test ]; then warnings=(-DLIVERSIM_WARNINGS_AS_ERRORS=ON); fi

begin_step "release build"
cmake --preset "$preset" "${warnings[@]}" >/dev/null
cmake --build --preset "$preset" --parallel "$(nproc)"
end_step

if [ "$command" = test ]; then
  # GUI and rendering tests need an X server: Xvfb provides one whether or not a display exists.
  # The longest tests carry a COST so that they start first. Then the budget: no test of the
  # release suite may take longer than packaging/test-budget.py allows (docs/ci.md).
  begin_step "release suite"
  results="$root/build/$preset/test-results.xml"
  "${xvfb[@]}" ctest --preset "$preset" --parallel "$(nproc)" --timeout 300 --output-junit "$results"
  end_step
  python3 "$root/packaging/test-budget.py" "$results"
  # Then each fuzz target fuzzed briefly: a clang build of what they need, with libFuzzer and the
  # sanitizers (docs/fuzzing.md). The same build, ASan + UBSan, runs the tests of the sessions
  # store, the roles, the training centre and the CLI's recording, crash and bad-input tests.
  begin_step "fuzz build"
  cmake --preset fuzz "${warnings[@]}" >/dev/null
  cmake --build --preset fuzz --parallel "$(nproc)"
  end_step
  begin_step "fuzz short runs"
  ctest --preset fuzz --parallel "$(nproc)"
  end_step
  begin_step "asan-inputs"
  ctest --preset asan-inputs --parallel "$(nproc)"
  end_step
  # Then the threaded parts under ThreadSanitizer: the programs their tests need, and those tests
  # (the whole suites under ASan and TSan take longer than CI allows: docs/sanitizers.md).
  begin_step "tsan build"
  cmake --preset tsan "${warnings[@]}" >/dev/null
  cmake --build --preset tsan --parallel "$(nproc)" --target liversim_threads_tests \
    liversim_station_tests liversim_storage_tests liversim_training_centre_tests \
    liversim_cli_record_tests liversim-cli liversim_session_writer_child
  end_step
  begin_step "tsan-threads"
  ctest --preset tsan-threads --parallel "$(nproc)"
  end_step
  exit 0
fi

if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  exec "$root/build/$preset/app/liversim"
fi
demo_png="$PWD/liversim-demo.png"
echo "liversim: no display found (DISPLAY and WAYLAND_DISPLAY are unset), so the workstation"
echo "cannot open a window. Running the headless demo instead; its screenshot: $demo_png"
exec "${xvfb[@]}" "$root/build/$preset/app/liversim-cli" demo --output "$demo_png"
