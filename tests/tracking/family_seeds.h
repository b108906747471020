// Seeds of the vessel family's sweeps, from an environment variable "FIRST-LAST" (or one seed):
// the sweeps run only when it is set (none in CI).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace vs {

inline std::vector<uint64_t> familySeedsFromEnv(const char* name) {
  std::vector<uint64_t> out;
  const char* env = std::getenv(name);
  if (!env) return out;
  const std::string s = env;
  const size_t dash = s.find('-');
  const uint64_t first = std::stoull(s.substr(0, dash)),
                 last = dash == std::string::npos ? first : std::stoull(s.substr(dash + 1));
  for (uint64_t k = first; k <= last; ++k) out.push_back(k);
  return out;
}

}  // namespace vs
