#include "docksim/profile_file.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "dockcore/drivers/toml_reader.hpp"

namespace docksim {
namespace {

using dockcore::DockProfile;
using dockcore::Real;
using dockcore::Vec2;
using dockcore::drivers::toml_reader::type_name;

[[noreturn]] void fail_at(const std::string& source, const toml::source_region& where, const std::string& what) {
  const int line = static_cast<int>(where.begin.line);
  const int column = static_cast<int>(where.begin.column);
  throw ProfileFileError(source + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what, line,
                         column);
}

/// A TOML integer or float as a double; nullopt for anything else.
bool number_of(const toml::node& n, double* out) {
  if (const auto* f = n.as_floating_point()) {
    *out = f->get();
    return true;
  }
  if (const auto* i = n.as_integer()) {
    *out = static_cast<double>(i->get());
    return true;
  }
  return false;
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6f", v);
  return buf;
}

std::string stem_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::string ext = ".toml";
  if (base.size() > ext.size() && base.compare(base.size() - ext.size(), ext.size(), ext) == 0) {
    base.resize(base.size() - ext.size());
  }
  return base;
}

}  // namespace

DockProfile parse_profile_toml(const std::string& text, const std::string& source_name,
                               const std::string& default_name) {
  toml::table root;
  try {
    root = toml::parse(std::string_view(text), std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    fail_at(source_name, e.source(), std::string(e.description()));
  }

  const toml::node* points = nullptr;
  toml::source_region points_where = root.source();
  std::string name = default_name;
  double contact_offset_m = 0;
  for (auto&& [key, value] : root) {
    const std::string k(key.str());
    if (k == "points") {
      points = &value;
      points_where = key.source();
    } else if (k == "contact_offset_m") {
      if (!number_of(value, &contact_offset_m)) {
        fail_at(source_name, value.source(), "contact_offset_m must be a number (metres), not " +
                                                  std::string(type_name(value)));
      }
      if (!std::isfinite(contact_offset_m)) fail_at(source_name, value.source(), "contact_offset_m is not finite");
    } else if (k == "name") {
      const auto* s = value.as_string();
      if (s == nullptr) fail_at(source_name, value.source(), "name must be a string, not " + std::string(type_name(value)));
      name = s->get();
      if (name.empty()) fail_at(source_name, value.source(), "name is empty");
      if (name.size() >= sizeof(DockProfile{}.name)) {
        fail_at(source_name, value.source(),
                "name is longer than " + std::to_string(sizeof(DockProfile{}.name) - 1) + " characters");
      }
    } else {
      fail_at(source_name, key.source(),
              "unknown key '" + k + "' (expected points, contact_offset_m, name)");
    }
  }
  if (points == nullptr) {
    // An empty document has no source region of its own; point at its start.
    toml::source_region start;
    start.begin = {1, 1};
    fail_at(source_name, start, "missing 'points' (an array of [x_m, y_m] pairs)");
  }
  const toml::array* arr = points->as_array();
  if (arr == nullptr) {
    fail_at(source_name, points->source(),
            "points must be an array of [x_m, y_m] pairs, not " + std::string(type_name(*points)));
  }
  if (arr->size() < 2) {
    fail_at(source_name, arr->source(), "points has " + std::to_string(arr->size()) + " point(s), at least 2 needed");
  }
  if (arr->size() > dockcore::kMaxProfileVertices) {
    fail_at(source_name, (*arr)[dockcore::kMaxProfileVertices].source(),
            "points has " + std::to_string(arr->size()) + " points, at most " +
                std::to_string(dockcore::kMaxProfileVertices) + " allowed");
  }
  std::vector<Vec2> v;
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& p = (*arr)[i];
    const toml::array* xy = p.as_array();
    if (xy == nullptr || xy->size() != 2) {
      fail_at(source_name, p.source(),
              "point " + std::to_string(i) + " must be [x_m, y_m] (two numbers), not " +
                  (xy == nullptr ? std::string(type_name(p)) : "an array of " + std::to_string(xy->size())));
    }
    double c[2] = {0, 0};
    for (std::size_t j = 0; j < 2; ++j) {
      const toml::node& e = (*xy)[j];
      if (!number_of(e, &c[j])) {
        fail_at(source_name, e.source(),
                "point " + std::to_string(i) + ": " + (j == 0 ? "x" : "y") + " must be a number, not " + type_name(e));
      }
      if (!std::isfinite(c[j])) fail_at(source_name, e.source(), "point " + std::to_string(i) + " is not finite");
    }
    const Vec2 q(static_cast<Real>(c[0]), static_cast<Real>(c[1]));
    if (!v.empty() && (q - v.back()).norm() < static_cast<Real>(0.001)) {
      fail_at(source_name, p.source(),
              "point " + std::to_string(i) + " is closer than 1 mm to point " + std::to_string(i - 1) +
                  " (degenerate segment)");
    }
    v.push_back(q);
  }

  DockProfile out;
  const dockcore::ProfileError err =
      dockcore::make_profile(v.data(), v.size(), static_cast<Real>(contact_offset_m), name.c_str(), out);
  if (err != dockcore::ProfileError::kOk) {
    // Everything make_profile checks was checked above; keep a positioned message for any future rule.
    fail_at(source_name, points_where, dockcore::to_string(err));
  }
  return out;
}

DockProfile load_profile_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProfileFileError("cannot open profile file " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ProfileFileError("cannot read profile file " + path);
  return parse_profile_toml(ss.str(), path, stem_of(path));
}

DockProfile resolve_profile(const std::string& name_or_path) {
  DockProfile p;
  if (dockcore::builtin_profile(name_or_path.c_str(), p) == dockcore::ProfileError::kOk) return p;
  const std::string ext = ".toml";
  const bool toml_name = name_or_path.size() > ext.size() &&
                         name_or_path.compare(name_or_path.size() - ext.size(), ext.size(), ext) == 0;
  if (toml_name || name_or_path.find('/') != std::string::npos) return load_profile_file(name_or_path);
  std::string names;
  for (const char* const* n = dockcore::kBuiltinProfileNames; *n != nullptr; ++n) {
    names += names.empty() ? "" : ", ";
    names += *n;
  }
  throw ProfileFileError("unknown profile '" + name_or_path + "': use a built-in name (" + names +
                         ") or a .toml file");
}

bool same_outline_as_builtin(const DockProfile& profile, const char* builtin_name) {
  DockProfile b;
  if (dockcore::builtin_profile(builtin_name, b) != dockcore::ProfileError::kOk) return false;
  if (b.vertex_count != profile.vertex_count) return false;
  for (std::size_t i = 0; i < b.vertex_count; ++i) {
    if ((b.vertices_m[i] - profile.vertices_m[i]).norm() > static_cast<Real>(1e-9)) return false;
  }
  return true;
}

std::string profile_to_toml(const DockProfile& profile) {
  std::string s = "name = \"";
  for (const char* c = profile.name; *c != '\0'; ++c) {
    if (*c == '"' || *c == '\\') s += '\\';
    s += *c;
  }
  s += "\"\npoints = [\n";
  for (std::size_t i = 0; i < profile.vertex_count; ++i) {
    s += "  [" + fmt(static_cast<double>(profile.vertices_m[i].x())) + ", " +
         fmt(static_cast<double>(profile.vertices_m[i].y())) + "],\n";
  }
  s += "]\n";
  return s;
}

}  // namespace docksim
