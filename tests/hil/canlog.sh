# Timing from a candump -L log (absolute CLOCK_REALTIME stamps), in awk (mawk: no gawk extensions): fast enough inside the TCG VM, where a
# Python start costs seconds. WheelCmdA = chassis base + 0 (default 0x100): bytes 0-3 wheel speeds, byte 4 bit 0
# DriveEnable (docs/can.md). "Zero" = both speeds 0 or the drive disabled.

# canlog_first_zero LOG T [ID]: stamp of the first zero WheelCmdA at or after T; "none" if there is none.
canlog_first_zero() {
  awk -v t="$2" -v id="${3:-100}" '
    function hex(s,  i, n) { n = 0; for (i = 1; i <= length(s); i++) n = n * 16 + index("0123456789ABCDEF", toupper(substr(s, i, 1))) - 1; return n }
    { ts = substr($1, 2, length($1) - 2) + 0; split($3, f, "#") }
    f[1] == id && ts >= t {
      en = hex(substr(f[2], 9, 2)) % 2
      if (substr(f[2], 1, 8) == "00000000" || en == 0) { printf "%.6f\n", ts; found = 1; exit }
    }
    END { if (!found) print "none" }' "$1"
}

# canlog_nonzero LOG T0 T1 [ID]: number of non-zero, enabled WheelCmdA frames with T0 <= stamp < T1.
canlog_nonzero() {
  awk -v t0="$2" -v t1="$3" -v id="${4:-100}" '
    function hex(s,  i, n) { n = 0; for (i = 1; i <= length(s); i++) n = n * 16 + index("0123456789ABCDEF", toupper(substr(s, i, 1))) - 1; return n }
    { ts = substr($1, 2, length($1) - 2) + 0; split($3, f, "#") }
    f[1] == id && ts >= t0 && ts < t1 {
      en = hex(substr(f[2], 9, 2)) % 2
      if (substr(f[2], 1, 8) != "00000000" && en == 1) n++
    }
    END { print n + 0 }' "$1"
}

# canlog_faults LOG [ID]: distinct non-zero fault codes of the DockStatus frames (host base + 1, default 0x181),
# in order. DockStatus bytes 2-3: fault code, little-endian.
canlog_faults() {
  awk -v id="${2:-181}" '
    function hex(s,  i, n) { n = 0; for (i = 1; i <= length(s); i++) n = n * 16 + index("0123456789ABCDEF", toupper(substr(s, i, 1))) - 1; return n }
    { split($3, f, "#") }
    f[1] == id {
      c = hex(substr(f[2], 7, 2) substr(f[2], 5, 2))
      if (c != 0 && c != last) { printf "%s%d", (n++ ? " " : ""), c; last = c }
    }
    END { print "" }' "$1"
}

# ms A B: (B - A) in whole milliseconds.
ms() { awk -v a="$1" -v b="$2" 'BEGIN { if (b == "none" || a == "") print "none"; else printf "%.0f\n", (b - a) * 1000 }'; }
