#include "args.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "io/volume_io.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/text.h"

namespace vs::cli {

namespace {

// The one number parser (util/text.h), shared with the viewer's script.
std::vector<std::string> split(const std::string& s, char sep) { return splitText(s, sep); }
std::string trimmed(const std::string& s) { return trimmedText(s); }
bool toDouble(const std::string& item, double& out) { return parseNumber(item, out); }
bool toInt(const std::string& item, int64_t& out) { return parseInteger(item, out); }

std::string countText(std::vector<size_t> counts) {
  std::string s;
  for (size_t i = 0; i < counts.size(); ++i) s += (i ? " or " : "") + std::to_string(counts[i]);
  return s;
}

}  // namespace

std::vector<double> parseNumbers(const std::string& text, const std::string& what, size_t count, size_t altCount) {
  std::vector<double> out;
  for (const auto& item : split(text, ',')) {
    double v = 0;
    if (!toDouble(item, v))
      throw UsageError(what + ": '" + text + "' is not a comma-separated list of numbers ('" + item + "')");
    out.push_back(v);
  }
  const bool ok = count == 0 || out.size() == count || (altCount != 0 && out.size() == altCount);
  if (!ok)
    throw UsageError(what + ": expected " +
                     countText(altCount ? std::vector<size_t>{count, altCount} : std::vector<size_t>{count}) +
                     " comma-separated numbers, got '" + text + "'");
  return out;
}

std::vector<double> parseNumbers(const std::string& text, const std::string& what, size_t count) {
  return parseNumbers(text, what, count, 0);
}

Vec3 parseVec3(const std::string& text, const std::string& what) {
  const auto v = parseNumbers(text, what, 3);
  return Vec3(v[0], v[1], v[2]);
}

Index3 parseIndex3(const std::string& text, const std::string& what) {
  const auto parts = split(text, ',');
  Index3 out{};
  if (parts.size() != 3) throw UsageError(what + ": expected x,y,z integers, got '" + text + "'");
  for (size_t i = 0; i < 3; ++i)
    if (!toInt(parts[i], out[i])) throw UsageError(what + ": '" + parts[i] + "' in '" + text + "' is not an integer");
  return out;
}

Index3 parseDims(const std::string& text, const std::string& what, int64_t maxSide, bool allow2D) {
  const auto parts = split(text, ',');
  if (parts.size() != 3 && !(allow2D && parts.size() == 2))
    throw UsageError(what + " '" + text + "': expected X,Y,Z" + std::string(allow2D ? " or X,Y" : ""));
  Index3 d{1, 1, 1};
  for (size_t i = 0; i < parts.size(); ++i) {
    if (!toInt(parts[i], d[i])) throw UsageError(what + " '" + text + "': '" + parts[i] + "' is not an integer");
    if (d[i] < 1 || d[i] > maxSide)
      throw UsageError(what + " '" + text + "': every size must be in 1.." + std::to_string(maxSide));
  }
  return d;
}

std::array<int, 2> parseImageSize(const std::string& text, const std::string& what, int maxSide, int minWidth,
                                  int minHeight) {
  const auto parts = split(text, 'x');
  int64_t w = 0, h = 0;
  if (parts.size() != 2 || !toInt(parts[0], w) || !toInt(parts[1], h))
    throw UsageError(what + ": expected WxH, e.g. 512x512, got '" + text + "'");
  if (w < minWidth || h < minHeight || w > maxSide || h > maxSide)
    throw UsageError(what + " " + text + ": width must be " + std::to_string(minWidth) + ".." +
                     std::to_string(maxSide) + " and height " + std::to_string(minHeight) + ".." +
                     std::to_string(maxSide));
  return {static_cast<int>(w), static_cast<int>(h)};
}

std::vector<std::vector<double>> parsePointList(const std::string& text, const std::string& what,
                                                std::vector<size_t> components, bool integers) {
  std::vector<std::vector<double>> points;
  const std::string expected = std::string(integers ? "integer " : "") + "points \"a,b;a,b;...\" (" +
                               countText(components) + " comma-separated numbers each)";
  for (const auto& item : split(text, ';')) {
    if (trimmed(item).empty()) continue;
    std::vector<double> p;
    bool ok = true;
    for (const auto& c : split(item, ',')) {
      int64_t i = 0;
      double d = 0;
      if (integers ? toInt(c, i) : toDouble(c, d))
        p.push_back(integers ? static_cast<double>(i) : d);
      else
        ok = false;
    }
    if (!ok || std::find(components.begin(), components.end(), p.size()) == components.end())
      throw UsageError(what + ": cannot parse '" + trimmed(item) + "' (expected " + expected + ")");
    points.push_back(std::move(p));
  }
  return points;
}

std::vector<Vec3> parseVec3List(const std::string& text, const std::string& what) {
  std::vector<Vec3> out;
  for (const auto& p : parsePointList(text, what, {3}, false)) out.emplace_back(p[0], p[1], p[2]);
  return out;
}

std::pair<std::string, std::string> splitLabel(const std::string& text, const std::string& what,
                                               const std::string& example) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0 || trimmed(text.substr(colon + 1)).empty())
    throw UsageError(what + " '" + text + "': expected LABEL:VALUES, e.g. " + example);
  return {text.substr(0, colon), text.substr(colon + 1)};
}

void requireExtension(const std::string& path, const std::string& what, const std::vector<std::string>& extensions) {
  std::string ext = fileExtension(path);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) return;
  std::string list;
  for (size_t i = 0; i < extensions.size(); ++i) list += (i ? ", " : "") + extensions[i];
  throw UsageError(what + " '" + path + "': unsupported file type '" + ext + "' (use " + list + ")");
}

const std::vector<std::string>& volumeOutputExtensions() { return volumeWriteExtensions(); }

}  // namespace vs::cli
