// All text parsing of the command line in one place: lists of numbers, sizes, points.
// Every parser throws vs::UsageError (exit status 2) with a message that starts with `what`
// (the option's name) and names the offending text, and never accepts trailing garbage,
// empty items, NaN or inf.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "volume/geometry.h"

namespace vs::cli {

// "a,b,c": exactly `count` finite numbers (count 0: one or more).
std::vector<double> parseNumbers(const std::string& text, const std::string& what, size_t count);
// "a,b,c" with one of two accepted counts (e.g. 2 or 3).
std::vector<double> parseNumbers(const std::string& text, const std::string& what, size_t count, size_t altCount);
// "x,y,z" finite numbers.
Vec3 parseVec3(const std::string& text, const std::string& what);
// "x,y,z" integers.
Index3 parseIndex3(const std::string& text, const std::string& what);
// "X,Y,Z" positive integers <= maxSide, or "X,Y" (Z = 1) when allow2D.
Index3 parseDims(const std::string& text, const std::string& what, int64_t maxSide, bool allow2D);
// "WxH" positive integers <= maxSide (and at least minWidth x minHeight).
std::array<int, 2> parseImageSize(const std::string& text, const std::string& what, int maxSide, int minWidth = 1,
                                  int minHeight = 1);

// ';'-separated list of points, each "a,b" or "a,b,c" (`components` lists the accepted
// counts, e.g. {2, 3}); blank items are skipped. Integers only when `integers`.
std::vector<std::vector<double>> parsePointList(const std::string& text, const std::string& what,
                                                std::vector<size_t> components, bool integers);
// ';'-separated "x,y,z" points (finite numbers); blank items are skipped.
std::vector<Vec3> parseVec3List(const std::string& text, const std::string& what);

// "LABEL:REST" split at the first ':' (both parts non-empty), e.g. "z+x+y:40,52,30";
// `example` is shown in the error.
std::pair<std::string, std::string> splitLabel(const std::string& text, const std::string& what,
                                               const std::string& example);

// Output types by extension: a usage error (exit 2) before any work, naming the accepted ones.
// Compared case-insensitively; ".nii.gz" counts as one extension.
void requireExtension(const std::string& path, const std::string& what, const std::vector<std::string>& extensions);
// The volume types writeVolume writes.
const std::vector<std::string>& volumeOutputExtensions();

}  // namespace vs::cli
