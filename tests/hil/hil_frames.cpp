// hil_frames: prints dockcore CAN v1 host command frames in cansend's ID#DATA form, so HIL cases (and users
// without dockctl) can command dockd over CAN with can-utils: cansend vcan0 $(hil_frames dock 0 1)
// Usage: hil_frames dock|cancel|undock|test DOCK_ID SEQUENCE [COUNTER] [HOST_BASE_ID]
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "dockcore/protocols/can/can_dockcore_v1.hpp"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: hil_frames dock|cancel|undock|test DOCK_ID SEQUENCE [COUNTER] [HOST_BASE_ID]\n");
    return 2;
  }
  namespace v1 = dockcore::can_v1;
  v1::HostCommandFrame m;
  const char* cmd = argv[1];
  if (std::strcmp(cmd, "dock") == 0) m.command = 1;
  else if (std::strcmp(cmd, "cancel") == 0) m.command = 2;
  else if (std::strcmp(cmd, "undock") == 0) m.command = 3;
  else if (std::strcmp(cmd, "test") == 0) m.command = 4;
  else m.command = static_cast<std::uint8_t>(std::strtoul(cmd, nullptr, 0));  // raw code: lets a case send junk
  m.dock_id = static_cast<std::uint16_t>(std::strtoul(argv[2], nullptr, 0));
  m.sequence = static_cast<std::uint16_t>(std::strtoul(argv[3], nullptr, 0));
  m.counter = static_cast<std::uint8_t>(argc > 4 ? std::strtoul(argv[4], nullptr, 0) : m.sequence);
  v1::Ids ids;
  if (argc > 5) ids.host_base = static_cast<std::uint32_t>(std::strtoul(argv[5], nullptr, 0));
  const dockcore::CanFrame f = v1::encode(ids, m);
  std::printf("%03X#", f.id);
  for (int i = 0; i < f.dlc; ++i) std::printf("%02X", f.data[i]);
  std::printf("\n");
  return 0;
}
