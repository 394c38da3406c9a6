// fuzz-links: core drivers dockd_lib
// dockd's UDP host requests: the host protocol's parse_host_request (flat JSON parser underneath) and the error reply
// it produces must never crash, and a refused request must leave the output untouched except for the echoed seq.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "host_protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dockd;
  HostRequest r;
  r.dock_id = 4242;
  const char* detail = nullptr;
  const HostErrorCode e = parse_host_request(reinterpret_cast<const char*>(data), size, r, detail);
  if (detail == nullptr) __builtin_trap();
  if (e != HostErrorCode::kNone && r.dock_id != 4242) __builtin_trap();
  char buf[512];
  const std::size_t n = format_host_error(buf, sizeof buf, r.has_seq, r.seq, e, detail);
  if (n >= sizeof buf) __builtin_trap();
  return 0;
}
