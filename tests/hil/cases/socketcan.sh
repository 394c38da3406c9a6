# The SocketCAN driver on a real vcan0: send/receive, id filter, timestamps, interface down/up recovery
# (tests/hil/socketcan_check.cpp prints its own PASS/FAIL lines), then can-utils interop: a frame from the driver is
# seen by candump and a cansend frame is received by the driver's filter.
"$BUILD/tests/socketcan_check" vcan0
check socketcan_check_exit test $? -eq 0
