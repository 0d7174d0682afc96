#!/usr/bin/env bash
# The Debian package: CPack builds it from this build tree; it is unpacked into a temporary root
# (dpkg -x, what dpkg would install) and its programs run from there, outside the build and
# source trees: --version, the shipped scenarios found beside the installed program, a headless
# scenario, and the workstation under the X server ctest runs in.
# Usage: test_package.sh BUILD_DIR VERSION
set -euo pipefail
build=$1
version=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

cpack --config "$build/CPackConfig.cmake" -B "$work/package" >"$work/cpack.log" 2>&1 ||
  { cat "$work/cpack.log"; fail "cpack could not build the package"; }
deb=$(ls "$work"/package/liversim_*.deb)
echo "package: $(basename "$deb") ($(du -h "$deb" | cut -f1))"

# Its control fields: name, version, and library dependencies found by dpkg-shlibdeps.
info=$(dpkg-deb --field "$deb" Package Version Depends)
echo "$info"
grep -qx "Package: liversim" <<<"$info" || fail "package name"
grep -qx "Version: $version" <<<"$info" || fail "version is not $version"
for library in libqt6widgets6 libvtk9 libsqlite3 libassimp libgmsh libqt6svg6; do
  grep -q "$library" <<<"$info" || fail "Depends lacks $library"
done
# Every dependency can be met on this machine (what apt-get install would check).
apt-get install --simulate --no-install-recommends "$deb" >"$work/apt.log" 2>&1 ||
  { cat "$work/apt.log"; fail "the package's dependencies cannot be met"; }

contents=$(dpkg-deb --contents "$deb")
for path in usr/bin/liversim usr/bin/liversim-cli \
  usr/share/applications/org.liversim.LiverSim.desktop \
  usr/share/icons/hicolor/scalable/apps/org.liversim.LiverSim.svg \
  usr/share/metainfo/org.liversim.LiverSim.metainfo.xml \
  usr/share/liversim/scenarios/palpation-hidden-lesion.json \
  usr/share/liversim/scenarios/schema/liversim-scenario-4.schema.json \
  usr/share/liversim/resources/icons/liversim.svg usr/share/doc/liversim/copyright; do
  grep -q "\./$path\$" <<<"$contents" || fail "the package lacks /$path"
done

root=$work/root
dpkg -x "$deb" "$root"
desktop-file-validate "$root/usr/share/applications/org.liversim.LiverSim.desktop" ||
  fail "desktop entry"
appstreamcli validate --no-net "$root/usr/share/metainfo/org.liversim.LiverSim.metainfo.xml" ||
  fail "AppStream metadata"

# The installed programs, run from elsewhere, with nothing of the build tree to fall back on.
cd "$work"
unset LIVERSIM_DATA_DIR
cli=$root/usr/bin/liversim-cli
[ "$("$cli" --version)" = "liversim-cli $version" ] || fail "liversim-cli --version"
validated=$("$cli" validate) || fail "the shipped scenarios do not validate"
echo "$validated"
grep -q "shipped scenarios in $root/usr/share/liversim/scenarios" <<<"$validated" ||
  fail "liversim-cli did not find the scenarios installed beside it"
[ "$(grep -c ': valid: ' <<<"$validated")" -ge 4 ] || fail "fewer than 4 shipped scenarios"
scenario=$root/usr/share/liversim/scenarios/retract-left-lobe.json
"$cli" simulate --scenario "$scenario" --time 0.05 | tee "$work/simulate.log"
grep -q "displacement of node" "$work/simulate.log" || fail "the headless scenario did not run"

gui=$root/usr/bin/liversim
"$gui" --version | grep -qx "liversim $version" || fail "liversim --version"
"$gui" --help | grep -q -- "--scenario" || fail "liversim --help"
[ -n "${DISPLAY:-}" ] || fail "DISPLAY is unset: run the tests under xvfb-run"
export XDG_CONFIG_HOME=$work/config XDG_DATA_HOME=$work/data QT_QPA_PLATFORM=xcb
"$gui" --language zh_CN --quit-after 3 --database "$work/sessions.sqlite" "$scenario" 2>"$work/gui.log" ||
  { cat "$work/gui.log"; fail "the installed workstation did not start and close cleanly"; }
[ -f "$work/sessions.sqlite" ] || fail "the installed workstation made no sessions database"
echo "PASS: the package installs, and its programs start"
