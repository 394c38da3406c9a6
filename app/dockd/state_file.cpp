#include "state_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace dockd {

const TaughtTarget* StateData::find(std::uint16_t dock_id) const {
  for (const TaughtTarget& t : targets) {
    if (t.dock_id == dock_id) return &t;
  }
  return nullptr;
}

void StateData::put(const TaughtTarget& t) {
  for (TaughtTarget& o : targets) {
    if (o.dock_id == t.dock_id) {
      o = t;
      return;
    }
  }
  targets.push_back(t);
}

bool with_taught_code(dockcore::DockProfile& profile, const TaughtTarget& t, dockcore::ProfileError* why) {
  if (why != nullptr) *why = dockcore::ProfileError::kOk;
  if (t.stripe_count == 0 || profile.reflector_count > 0) return false;
  dockcore::DockProfile coded = profile;
  for (std::size_t q = 0; q < t.stripe_count; ++q) {
    const dockcore::ProfileError e = dockcore::add_reflector(coded, t.stripes[q]);
    if (e != dockcore::ProfileError::kOk) {
      if (why != nullptr) *why = e;
      return false;
    }
  }
  profile = coded;
  return true;
}

std::uint32_t crc32_ieee(const char* data, std::size_t len) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < len; ++i) {
    c ^= static_cast<std::uint8_t>(data[i]);
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

bool checked_body(const std::string& text, std::size_t* body_size, std::string& error) {
  const std::size_t pos = text.rfind("crc32 ");
  if (pos == std::string::npos || (pos > 0 && text[pos - 1] != '\n')) {
    error = "no checksum line (truncated?)";
    return false;
  }
  unsigned crc = 0;
  char tail = 0;
  if (std::sscanf(text.c_str() + pos, "crc32 %8x%c", &crc, &tail) != 2 || tail != '\n' || pos + 15 != text.size()) {
    error = "malformed checksum line";
    return false;
  }
  if (crc32_ieee(text.data(), pos) != crc) {
    error = "checksum mismatch (file corrupted)";
    return false;
  }
  *body_size = pos;
  return true;
}

std::string serialize_state(const StateData& s) {
  std::string body = "dockd-state 1\n";
  for (const TaughtTarget& t : s.targets) {
    char line[256];
    std::snprintf(line, sizeof line, "target %u %.9f %.9f %.9f %u %.6f %" PRIu64 "\n", t.dock_id,
                  static_cast<double>(t.target.x_m), static_cast<double>(t.target.y_m),
                  static_cast<double>(t.target.yaw_rad), t.scans, t.spread_m, t.taught_unix_s);
    body += line;
    if (t.stripe_count > 0) {
      // The code on its own line: an older reader's target lines stay as they were.
      std::snprintf(line, sizeof line, "code %u %u %.6f %u", t.dock_id, t.code_scans, t.code_spread_m, t.stripe_count);
      body += line;
      for (std::size_t q = 0; q < t.stripe_count && q < dockcore::kMaxReflectors; ++q) {
        std::snprintf(line, sizeof line, " %u %.6f %.6f", t.stripes[q].segment,
                      static_cast<double>(t.stripes[q].from_m), static_cast<double>(t.stripes[q].to_m));
        body += line;
      }
      body += '\n';
    }
  }
  char crc[32];
  std::snprintf(crc, sizeof crc, "crc32 %08x\n", crc32_ieee(body.data(), body.size()));
  return body + crc;
}

namespace {

/// Parses a `code <id> <scans> <spread_m> <n> (<segment> <from_m> <to_m>){n}` line into `t`'s code fields; false +
/// reason otherwise (t's code untouched). O(line).
bool parse_code_line(const std::string& line, TaughtTarget& t, unsigned* id_out, std::string& why) {
  const char* p = line.c_str();
  unsigned id = 0, scans = 0, n = 0;
  double spread = 0;
  int used = 0;
  if (std::sscanf(p, "code %u %u %lf %u%n", &id, &scans, &spread, &n, &used) != 4 || id > 65535 || scans > 65535 ||
      !std::isfinite(spread) || spread < 0) {
    why = "expected 'code <dock_id> <scans> <spread_m> <stripes> <segment> <from_m> <to_m> ...'";
    return false;
  }
  *id_out = id;
  if (n < 1 || n > dockcore::kMaxReflectors) {
    why = "1 to " + std::to_string(dockcore::kMaxReflectors) + " stripes";
    return false;
  }
  p += used;
  dockcore::ReflectorStripe st[dockcore::kMaxReflectors];
  for (unsigned q = 0; q < n; ++q) {
    unsigned seg = 0;
    double from = 0, to = 0;
    if (std::sscanf(p, " %u %lf %lf%n", &seg, &from, &to, &used) != 3) {
      why = "stripe " + std::to_string(q + 1) + " of " + std::to_string(n) + " missing or malformed";
      return false;
    }
    p += used;
    if (seg + 1 >= dockcore::kMaxProfileVertices || !std::isfinite(from) || !std::isfinite(to) || from < 0 ||
        to < from + 0.01 - 1e-9) {
      why = "stripe " + std::to_string(q + 1) + " off its segment or shorter than 1 cm";
      return false;
    }
    if (q > 0 &&
        (seg < st[q - 1].segment || (seg == st[q - 1].segment && from < static_cast<double>(st[q - 1].to_m)))) {
      why = "stripe " + std::to_string(q + 1) + " out of order or overlapping the one before";
      return false;
    }
    st[q].segment = static_cast<std::uint8_t>(seg);
    st[q].from_m = static_cast<dockcore::Real>(from);
    st[q].to_m = static_cast<dockcore::Real>(to);
  }
  if (*p != '\0') {
    why = "more than " + std::to_string(n) + " stripes";
    return false;
  }
  for (unsigned q = 0; q < n; ++q) t.stripes[q] = st[q];
  t.stripe_count = static_cast<std::uint8_t>(n);
  t.code_scans = static_cast<std::uint16_t>(scans);
  t.code_spread_m = spread;
  return true;
}

}  // namespace

bool parse_state(const std::string& text, StateData& out, std::string& error, std::vector<std::string>* warnings) {
  std::size_t pos = 0;
  if (!checked_body(text, &pos, error)) return false;
  std::istringstream in(text.substr(0, pos));
  std::string line;
  if (!std::getline(in, line) || line != "dockd-state 1") {
    error = "unknown header '" + line + "'";
    return false;
  }
  StateData s;
  std::size_t line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.compare(0, 5, "code ") == 0) {
      TaughtTarget code;
      unsigned id = 0;
      std::string why;
      TaughtTarget* target = nullptr;
      if (parse_code_line(line, code, &id, why)) {
        for (TaughtTarget& o : s.targets) {
          if (o.dock_id == id) target = &o;
        }
        if (target == nullptr) why = "no target line of dock " + std::to_string(id) + " before it";
      }
      if (target == nullptr) {
        if (warnings != nullptr) {
          warnings->push_back("line " + std::to_string(line_no) + ": bad code line '" + line.substr(0, 200) + "' (" +
                              why + "): left out, dock " + std::to_string(id) + " has no taught code");
        }
        continue;
      }
      for (std::size_t q = 0; q < code.stripe_count; ++q) target->stripes[q] = code.stripes[q];
      target->stripe_count = code.stripe_count;
      target->code_scans = code.code_scans;
      target->code_spread_m = code.code_spread_m;
      target->code_line = line_no;
      continue;
    }
    TaughtTarget t;
    unsigned id = 0, scans = 0;
    double x = 0, y = 0, yaw = 0, spread = 0;
    std::uint64_t when = 0;
    int used = 0;
    if (std::sscanf(line.c_str(), "target %u %lf %lf %lf %u %lf %" SCNu64 "%n", &id, &x, &y, &yaw, &scans, &spread,
                    &when, &used) != 7 ||
        static_cast<std::size_t>(used) != line.size() || id > 65535 || scans > 65535) {
      error = "bad line '" + line + "'";
      return false;
    }
    t.dock_id = static_cast<std::uint16_t>(id);
    t.target = dockcore::Pose2{static_cast<dockcore::Real>(x), static_cast<dockcore::Real>(y),
                               static_cast<dockcore::Real>(yaw)};
    t.scans = static_cast<std::uint16_t>(scans);
    t.spread_m = spread;
    t.taught_unix_s = when;
    s.put(t);
  }
  out = s;
  return true;
}

FileRead read_bounded(const std::string& path, std::size_t max_bytes, std::string& text, std::string& why) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (errno == ENOENT) return FileRead::kMissing;
    why = std::string("cannot open: ") + std::strerror(errno);
    return FileRead::kUnreadable;
  }
  // Bounded: a legitimate file is small; a runaway one is corrupt, not read whole.
  text.assign(max_bytes + 1, '\0');
  in.read(&text[0], static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > max_bytes) {
    why = "larger than " + std::to_string(max_bytes) + " bytes";
    return FileRead::kTooLarge;
  }
  return FileRead::kOk;
}

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : (slash == 0 ? std::string("/") : path.substr(0, slash));
}

namespace {

/// Writes "WHAT PATH[ to TO]: strerror(errno)" into `error` (when there is room for it); false.
bool fail_with_errno(char* error, std::size_t error_size, const char* what, const char* path,
                     const char* to = nullptr) {
  const int e = errno;
  if (error != nullptr && error_size > 0) {
    std::snprintf(error, error_size, "%s %s%s%s: %s", what, path, to != nullptr ? " to " : "", to != nullptr ? to : "",
                  std::strerror(e));
  }
  return false;
}

}  // namespace

bool write_synced(const char* tmp, const char* data, std::size_t len, char* error, std::size_t error_size) {
  const int fd = ::open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail_with_errno(error, error_size, "cannot create", tmp);
  std::size_t done = 0;
  while (done < len) {
    const ssize_t n = ::write(fd, data + done, len - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      fail_with_errno(error, error_size, "cannot write", tmp);
      ::close(fd);
      ::unlink(tmp);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    fail_with_errno(error, error_size, "cannot fsync", tmp);
    ::close(fd);
    ::unlink(tmp);
    return false;
  }
  if (::close(fd) != 0) {
    fail_with_errno(error, error_size, "cannot close", tmp);
    ::unlink(tmp);
    return false;
  }
  return true;
}

bool replace_synced(const char* tmp, const char* path, const char* dir, char* error, std::size_t error_size) {
  if (std::rename(tmp, path) != 0) {
    fail_with_errno(error, error_size, "cannot rename", tmp, path);
    ::unlink(tmp);
    return false;
  }
  const int dfd = ::open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
  return true;
}

namespace {

enum class ReadResult { kOk, kMissing, kBad };

ReadResult read_file(const std::string& path, StateData& out, std::string& why,
                     std::vector<std::string>* warnings = nullptr) {
  std::string text;
  const FileRead r = read_bounded(path, kMaxStateFileBytes, text, why);
  if (r != FileRead::kOk) return r == FileRead::kMissing ? ReadResult::kMissing : ReadResult::kBad;
  return parse_state(text, out, why, warnings) ? ReadResult::kOk : ReadResult::kBad;
}

}  // namespace

StateLoadStatus load_state(const std::string& path, StateData& out, std::string& message,
                           std::vector<std::string>* warnings) {
  std::string why;
  std::vector<std::string> notes;
  auto report = [&](const std::string& file) {
    if (warnings == nullptr) return;
    for (const std::string& n : notes) warnings->push_back(file + ":" + n.substr(5));  // "line N: ..." -> "FILE:N: ..."
  };
  const ReadResult r = read_file(path, out, why, &notes);
  if (r == ReadResult::kOk) {
    report(path);
    return StateLoadStatus::kOk;
  }
  std::string bak_why;
  StateData bak;
  notes.clear();
  const ReadResult rb = read_file(path + ".bak", bak, bak_why, &notes);
  if (rb == ReadResult::kOk) report(path + ".bak");
  if (r == ReadResult::kMissing) {
    if (rb == ReadResult::kOk) {
      // A crash between the two renames of save_state leaves only the backup.
      out = bak;
      message = "state file " + path + " missing; using the backup " + path + ".bak";
      return StateLoadStatus::kRecoveredBackup;
    }
    out = StateData{};
    return StateLoadStatus::kMissing;
  }
  // Keep the bad file for inspection, out of the way of the next save.
  std::rename(path.c_str(), (path + ".corrupt").c_str());
  if (rb == ReadResult::kOk) {
    out = bak;
    message = "state file " + path + " is corrupt (" + why + "), moved to " + path + ".corrupt; using the last good copy " +
              path + ".bak";
    return StateLoadStatus::kRecoveredBackup;
  }
  out = StateData{};
  message = "state file " + path + " is corrupt (" + why + "), moved to " + path + ".corrupt; no good backup: taught targets lost";
  return StateLoadStatus::kCorruptNoBackup;
}

bool save_state(const std::string& path, const StateData& s, std::string& error) {
  const std::string text = serialize_state(s);
  const std::string tmp = path + ".tmp";
  char why[512];
  if (!write_synced(tmp.c_str(), text.data(), text.size(), why, sizeof why)) {
    error = why;
    return false;
  }
  // The current file becomes the backup only if it is good: a corrupt file must never replace a good backup.
  StateData current;
  std::string bad;
  if (read_file(path, current, bad) == ReadResult::kOk) std::rename(path.c_str(), (path + ".bak").c_str());
  if (!replace_synced(tmp.c_str(), path.c_str(), directory_of(path).c_str(), why, sizeof why)) {
    error = why;
    return false;
  }
  return true;
}

}  // namespace dockd
