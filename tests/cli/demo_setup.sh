#!/usr/bin/env bash
# tools/setup-deps and tools/demo without touching the system: fake cmake / dpkg-query / apt-get / sudo first on PATH.
#  setup-deps --demo --list: the demo's packages (build and libraries), none of the test toolchain (qemu, kernel,
#  clang, cross compilers); --list without --demo holds both; an unknown argument exits 2.
#  demo: exit 2 when the dependencies cannot be installed, when configuring fails and when building fails.
#  A mirror whose armhf package index cannot be fetched: setup-deps installs everything else (arm64 included) and
#  tools/test's armhf stage says it skips and why, and passes.
set -u
# Run from tools/test, the environment says the dependencies were checked: these cases check them again.
unset DOCKCORE_DEPS_CHECKED
SRC=$1 WORK=$2
rm -rf "$WORK" && mkdir -p "$WORK/bin"
fail() { echo "FAIL: $*" >&2; exit 1; }

demo_list=$("$SRC/tools/setup-deps" --demo --list) || fail "setup-deps --demo --list: exit $?"
full_list=$("$SRC/tools/setup-deps" --list) || fail "setup-deps --list: exit $?"
for p in cmake ninja-build g++ libcli11-dev libeigen3-dev; do
  grep -qx "$p" <<<"$demo_list" || fail "demo list lacks $p"
done
for p in qemu-system-x86 linux-image-amd64 clang-14 g++-aarch64-linux-gnu gcc-arm-none-eabi valgrind; do
  grep -qx "$p" <<<"$demo_list" && fail "demo list holds the test toolchain's $p"
  grep -qx "$p" <<<"$full_list" || fail "full list lacks $p"
done
"$SRC/tools/setup-deps" --bogus 2>/dev/null; rc=$?
[ $rc -eq 2 ] || fail "setup-deps --bogus: exit $rc (want 2)"

# Fakes: every package installed (or none, with FAKE_MISSING=1; none of the foreign ones with FAKE_MISSING=foreign);
# apt-get fails (with FAKE_APT=armhf-index: the update fails on the armhf index unless told to leave armhf out, and
# the install fails if it names an armhf package); cmake fails at FAKE_CMAKE_FAIL; dpkg knows amd64, arm64, armhf.
cat > "$WORK/bin/dpkg-query" <<'SH'
#!/bin/sh
for p; do :; done
[ "${FAKE_MISSING:-0}" = 1 ] && exit 1
if [ "${FAKE_MISSING:-0}" = foreign ]; then case "$p" in *:arm64|*:armhf) exit 1 ;; esac; fi
printf 'install ok installed'
SH
cat > "$WORK/bin/apt-get" <<'SH'
#!/bin/sh
echo "fake apt-get $*" >&2
[ "${FAKE_APT:-}" = armhf-index ] || exit 100
case " $* " in
  *" update "*)
    case "$*" in *APT::Architectures=amd64,arm64*) exit 0 ;; esac
    echo "E: Failed to fetch http://deb.example/debian-security/dists/bookworm-security/main/binary-armhf/Packages.xz  File has unexpected size (356624 != 356976). Mirror sync in progress?"
    exit 100 ;;
  *" install "*) case "$*" in *:armhf*) exit 100 ;; esac; exit 0 ;;
esac
exit 100
SH
cat > "$WORK/bin/dpkg" <<'SH'
#!/bin/sh
case "$1" in
  --print-architecture) echo amd64 ;;
  --print-foreign-architectures) printf 'arm64\narmhf\n' ;;
esac
exit 0
SH
cat > "$WORK/bin/sudo" <<'SH'
#!/bin/sh
exec "$@"
SH
cat > "$WORK/bin/cmake" <<'SH'
#!/bin/sh
case "$1" in
  --preset) [ "${FAKE_CMAKE_FAIL:-}" = configure ] && exit 1 ;;
  --build) [ "${FAKE_CMAKE_FAIL:-}" = build ] && exit 1 ;;
esac
exit 0
SH
chmod +x "$WORK/bin/"*

run_demo() { PATH="$WORK/bin:$PATH" DOCKCORE_APT_RETRY_S=0 "$SRC/tools/demo" >"$WORK/demo.out" 2>&1; echo $?; }
rc=$(FAKE_MISSING=1 run_demo)
[ "$rc" -eq 2 ] || fail "demo, install fails: exit $rc (want 2): $(cat "$WORK/demo.out")"
grep -q "installing .* with apt-get: cmake ninja-build" "$WORK/demo.out" || fail "setup-deps does not say what it installs: $(cat "$WORK/demo.out")"
# A mirror caught mid-sync: the install is tried three times before setup-deps gives up.
[ "$(grep -c "fake apt-get install" "$WORK/demo.out")" -eq 3 ] || fail "install not tried 3 times: $(cat "$WORK/demo.out")"
grep -q "qemu" "$WORK/demo.out" && fail "demo setup mentions qemu: $(cat "$WORK/demo.out")"
rc=$(FAKE_CMAKE_FAIL=configure run_demo)
[ "$rc" -eq 2 ] || fail "demo, configure fails: exit $rc (want 2): $(cat "$WORK/demo.out")"
grep -q "configuring the default preset failed" "$WORK/demo.out" || fail "configure message: $(cat "$WORK/demo.out")"
rc=$(FAKE_CMAKE_FAIL=build run_demo)
[ "$rc" -eq 2 ] || fail "demo, build fails: exit $rc (want 2): $(cat "$WORK/demo.out")"
grep -q "building dock-sim failed" "$WORK/demo.out" || fail "build message: $(cat "$WORK/demo.out")"

out="$WORK/test.out"
PATH="$WORK/bin:$PATH" DOCKCORE_APT_RETRY_S=0 FAKE_MISSING=foreign FAKE_APT=armhf-index DOCKCORE_STAGES=armhf \
  "$SRC/tools/test" >"$out" 2>&1
rc=$?
[ "$rc" -eq 0 ] || fail "tools/test, armhf index unavailable: exit $rc (want 0): $(cat "$out")"
grep -q "fake apt-get install .*libcpputest-dev:arm64" "$out" || fail "arm64 packages not installed: $(cat "$out")"
grep "fake apt-get install" "$out" | tail -1 | grep -q ":armhf" && fail "last install still names armhf: $(cat "$out")"
grep -q "not installing: libcpputest-dev:armhf" "$out" || fail "setup-deps does not name what it leaves out: $(cat "$out")"
grep -q "armhf: SKIPPED: .*libcpputest-dev:armhf" "$out" || fail "armhf stage does not say it skips: $(cat "$out")"
grep -Eq "^armhf +skipped" "$out" || fail "summary lacks 'armhf skipped': $(cat "$out")"
echo "demo_setup: OK"
