// hil_udp: the host side of dockd's UDP protocol for the HIL fault matrix, in C++ because Python in the TCG VM takes
// tens of seconds to start and cannot pace 1000 requests/s.
//   hil_udp send PORT PAYLOAD          sends one datagram to 127.0.0.1:PORT, prints the reply (3 s), exit 0 / 1
//   hil_udp flood PORT RATE SECONDS    RATE requests/s (status and dock alternately) for SECONDS, reading every reply;
//                                      prints "sent N replies M achieved_rate R max_late_ms L rejected K busy B"
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

double now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

int open_socket(int port, sockaddr_in& to) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
  if (fd < 0) {
    std::perror("socket");
    std::exit(2);
  }
  int rcv = 1 << 20;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcv, sizeof rcv);
  to = {};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return fd;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 4 && std::strcmp(argv[1], "send") == 0) {
    sockaddr_in to{};
    const int fd = open_socket(std::atoi(argv[2]), to);
    ::sendto(fd, argv[3], std::strlen(argv[3]), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 3000) <= 0) {
      std::printf("no reply\n");
      return 1;
    }
    char buf[2048];
    const ssize_t n = ::recv(fd, buf, sizeof buf - 1, 0);
    if (n <= 0) return 1;
    buf[n] = 0;
    std::fputs(buf, stdout);
    if (buf[n - 1] != '\n') std::fputc('\n', stdout);
    return 0;
  }
  if (argc >= 5 && std::strcmp(argv[1], "flood") == 0) {
    sockaddr_in to{};
    const int fd = open_socket(std::atoi(argv[2]), to);
    const double rate = std::atof(argv[3]), seconds = std::atof(argv[4]);
    long sent = 0, replies = 0, rejected = 0, busy = 0;
    double max_late = 0;
    const double t0 = now_s();
    char req[128], buf[2048];
    auto drain = [&] {
      for (;;) {
        const ssize_t n = ::recv(fd, buf, sizeof buf - 1, 0);
        if (n <= 0) return;
        buf[n] = 0;
        ++replies;
        if (std::strstr(buf, "\"ok\":false") != nullptr) ++rejected;
        if (std::strstr(buf, "\"code\":9") != nullptr) ++busy;
      }
    };
    for (;;) {
      const double t = now_s() - t0;
      if (t >= seconds) break;
      const long due = static_cast<long>(t * rate) + 1;
      if (due - sent > 1) max_late = std::max(max_late, (static_cast<double>(due - sent) - 1) / rate);
      while (sent < due) {
        const int n = (sent % 2 == 0) ? std::snprintf(req, sizeof req, "{\"cmd\":\"status\",\"seq\":%ld}", sent)
                                      : std::snprintf(req, sizeof req, "{\"cmd\":\"dock\",\"dock_id\":0,\"seq\":%ld}", sent);
        if (::sendto(fd, req, static_cast<size_t>(n), 0, reinterpret_cast<sockaddr*>(&to), sizeof to) < 0) break;
        ++sent;
      }
      drain();
      timespec ts{0, 500 * 1000};
      ::nanosleep(&ts, nullptr);
    }
    const double end = now_s() + 1.0;
    while (now_s() < end && replies < sent) {
      drain();
      timespec ts{0, 5 * 1000 * 1000};
      ::nanosleep(&ts, nullptr);
    }
    std::printf("sent %ld replies %ld achieved_rate %.0f max_late_ms %.0f rejected %ld busy %ld\n", sent, replies,
                static_cast<double>(sent) / seconds, max_late * 1000, rejected, busy);
    return 0;
  }
  std::fprintf(stderr, "usage: hil_udp send PORT PAYLOAD | flood PORT RATE SECONDS\n");
  return 2;
}
