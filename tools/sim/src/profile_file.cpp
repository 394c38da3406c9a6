#include "docksim/profile_file.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "dockcore/params/profile_toml.hpp"

namespace docksim {
namespace {

using dockcore::DockProfile;
using dockcore::Real;

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6f", v);
  return buf;
}

}  // namespace

DockProfile parse_profile_toml(const std::string& text, const std::string& source_name,
                               const std::string& default_name) {
  return dockcore::params::profile_toml::parse<ProfileFileError>(text, source_name, default_name);
}

DockProfile load_profile_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProfileFileError("cannot open profile file " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ProfileFileError("cannot read profile file " + path);
  return parse_profile_toml(ss.str(), path, dockcore::params::profile_toml::name_from_path(path));
}

DockProfile resolve_profile(const std::string& name_or_path) {
  DockProfile p;
  if (dockcore::builtin_profile(name_or_path.c_str(), p) == dockcore::ProfileError::kOk) return p;
  const std::string ext = ".toml";
  const bool toml_name =
      name_or_path.size() > ext.size() && name_or_path.compare(name_or_path.size() - ext.size(), ext.size(), ext) == 0;
  if (toml_name || name_or_path.find('/') != std::string::npos) return load_profile_file(name_or_path);
  std::string names;
  for (const char* const* n = dockcore::kBuiltinProfileNames; *n != nullptr; ++n) {
    names += names.empty() ? "" : ", ";
    names += *n;
  }
  throw ProfileFileError("unknown profile '" + name_or_path + "': use a built-in name (" + names + ") or a .toml file");
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
  // A coded dock's floor is the estimator's whatever the outline's (DockProfile::min_inliers): not written.
  if (profile.min_inliers > 0 && profile.reflector_count == 0) {
    s += "min_inliers = " + std::to_string(profile.min_inliers) + "\n";
  }
  const dockcore::DockMounting& m = profile.mounting;
  if (m.kind != dockcore::DockMountKind::kUnknown) {
    s += "\n[mounting]\nkind = \"" + std::string(dockcore::to_string(m.kind)) + "\"\n";
    if (m.kind == dockcore::DockMountKind::kWall) {
      s += "wall_gap_m = [" + fmt(static_cast<double>(m.wall_gap_min_m)) + ", " +
           fmt(static_cast<double>(m.wall_gap_max_m)) + "]\n";
    }
  }
  for (std::size_t i = 0; i < profile.reflector_count; ++i) {
    const dockcore::ReflectorStripe& r = profile.reflectors[i];
    s += "\n[[reflectors]]\nsegment = " + std::to_string(r.segment) +
         "\nfrom_m = " + fmt(static_cast<double>(r.from_m)) + "\nto_m = " + fmt(static_cast<double>(r.to_m)) + "\n";
  }
  return s;
}

}  // namespace docksim
