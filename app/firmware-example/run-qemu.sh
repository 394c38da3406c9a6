#!/bin/sh
# Runs the example firmware on a QEMU Arm machine with semihosting for output and exit status.
#   run-qemu.sh MACHINE FIRMWARE.elf    MACHINE as CMake's DOCKCORE_FW_BOARD: mps2-an500 (Cortex-M7), mps2-an386 (M4)
# Exit 77 (ctest: skipped) when qemu-system-arm is not installed; 2 for a usage error.
set -eu
[ $# -eq 2 ] || { echo "usage: $0 MACHINE FIRMWARE.elf" >&2; exit 2; }
machine=$1
elf=$2
[ -f "$elf" ] || { echo "$0: no such firmware: $elf" >&2; exit 2; }
command -v qemu-system-arm >/dev/null 2>&1 || { echo "qemu-system-arm not installed: skipped"; exit 77; }
qemu-system-arm -M help | grep -q "^$machine " || { echo "$0: qemu-system-arm has no machine $machine" >&2; exit 2; }
# -icount: virtual time advances 2^6 ns per instruction, so the firmware's SysTick cost counters count instructions.
exec timeout 240 qemu-system-arm -M "$machine" -icount shift=6,align=off,sleep=off -nographic -monitor none -serial none \
  -semihosting-config enable=on,target=native -kernel "$elf"
