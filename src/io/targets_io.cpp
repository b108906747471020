#include "io/targets_io.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/io_internal.h"
#include "util/error.h"

namespace vs {

namespace {

std::string where(const std::string& path) { return "targets file '" + path + "'"; }

Vec3 jsonPoint(const nlohmann::json& p, const std::string& path, const std::string& what) {
  const nlohmann::json& q = p.is_object() && p.contains("voxel") ? p["voxel"] : p;
  if (!q.is_array() || q.size() != 3 || !q[0].is_number() || !q[1].is_number() || !q[2].is_number())
    throw IoError(where(path) + ": " + what + " is not [x,y,z] (three numbers): " + q.dump().substr(0, 80));
  return Vec3(q[0].get<double>(), q[1].get<double>(), q[2].get<double>());
}

TargetList parseJson(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(where(path) + ": invalid JSON: " + e.what());
  }
  TargetList out;
  const nlohmann::json* list = &j;
  if (j.is_object()) {
    for (const char* key : {"root", "root_voxel"})
      if (j.contains(key)) out.root = jsonPoint(j[key], path, std::string("\"") + key + "\"");
    list = j.contains("terminals") ? &j["terminals"] : (j.contains("targets") ? &j["targets"] : nullptr);
    if (!list) throw IoError(where(path) + ": no \"terminals\" or \"targets\" array");
  }
  if (!list->is_array()) throw IoError(where(path) + ": the targets are not an array");
  for (size_t i = 0; i < list->size(); ++i)
    out.targets.push_back(jsonPoint((*list)[i], path, "target #" + std::to_string(i + 1)));
  return out;
}

// "x y z" or "x,y,z" (spaces and commas both separate).
bool parseLine(std::string line, Vec3& p) {
  for (char& c : line)
    if (c == ',') c = ' ';
  std::istringstream in(line);
  double v[3];
  std::string rest;
  if (!(in >> v[0] >> v[1] >> v[2]) || (in >> rest)) return false;
  for (double x : v)
    if (!std::isfinite(x)) return false;
  p = Vec3(v[0], v[1], v[2]);
  return true;
}

TargetList parseText(const std::string& text, const std::string& path) {
  TargetList out;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    Vec3 p;
    if (!parseLine(line, p))
      throw IoError(where(path) + " line " + std::to_string(n) +
                    ": expected three numbers \"x y z\" or \"x,y,z\", got '" + line.substr(0, 80) + "'");
    out.targets.push_back(p);
  }
  return out;
}

}  // namespace

TargetList parseTargetList(const std::string& text, const std::string& path) {
  const auto first = text.find_first_not_of(" \t\r\n");
  const bool json = first != std::string::npos && (text[first] == '{' || text[first] == '[');
  TargetList out = json ? parseJson(text, path) : parseText(text, path);
  for (size_t i = 0; i < out.targets.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(out.targets[i][c]))
        throw IoError(where(path) + ": target #" + std::to_string(i + 1) + " is not finite");
  if (out.targets.empty()) throw IoError(where(path) + ": holds no target");
  return out;
}

TargetList readTargetList(const std::string& path) {
  return parseTargetList(io_detail::readFileBytes(path, false), path);
}

}  // namespace vs
