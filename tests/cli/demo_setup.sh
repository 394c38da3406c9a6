#!/usr/bin/env bash
# tools/setup-deps and tools/demo without touching the system: fake cmake / dpkg-query / apt-get / sudo first on PATH.
#  setup-deps --demo --list: the demo's packages (build and libraries), none of the test toolchain (qemu, kernel,
#  clang, cross compilers); --list without --demo holds both; an unknown argument exits 2.
#  demo: exit 2 when the dependencies cannot be installed, when configuring fails and when building fails.
set -u
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

# Fakes: every package installed (or none, with FAKE_MISSING=1); apt-get fails; cmake fails at FAKE_CMAKE_FAIL.
cat > "$WORK/bin/dpkg-query" <<'SH'
#!/bin/sh
[ "${FAKE_MISSING:-0}" = 1 ] && exit 1
printf 'install ok installed'
SH
cat > "$WORK/bin/apt-get" <<'SH'
#!/bin/sh
echo "fake apt-get $*" >&2
exit 100
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
echo "demo_setup: OK"
