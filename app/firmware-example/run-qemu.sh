#!/bin/sh
# Runs the example firmware on QEMU's mps2-an500 (Cortex-M7, FPv5-D16) with semihosting for output and exit status.
# Exit 77 (ctest: skipped) when qemu-system-arm is not installed.
command -v qemu-system-arm >/dev/null 2>&1 || { echo "qemu-system-arm not installed: skipped"; exit 77; }
exec timeout 240 qemu-system-arm -M mps2-an500 -nographic -monitor none -serial none \
  -semihosting-config enable=on,target=native -kernel "$1"
