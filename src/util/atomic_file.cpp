#include "util/atomic_file.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace fs = std::filesystem;

namespace vs {

std::string fileExtension(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char* dbl : {".nii.gz", ".tar.gz", ".vtk.gz"}) {
    const std::string d(dbl);
    if (name.size() > d.size() && name.compare(name.size() - d.size(), d.size(), d) == 0) return d;
  }
  const auto dot = name.rfind('.');
  if (dot == std::string::npos || dot == 0) return {};
  return name.substr(dot);
}

void checkOutputPath(const std::string& path) {
  if (path.empty()) throw IoError("output path is empty");
  fs::path p(path);
  fs::path dir = p.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError(path + ": output directory '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw IoError(path + ": output directory '" + dir.string() + "' is not writable");
  if (fs::is_directory(p, ec)) throw IoError(path + ": is a directory");
}

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  checkOutputPath(path);
  static std::atomic<unsigned> counter{0};
  fs::path p(path);
  const std::string ext = fileExtension(path);
  // Built with append: GCC 12 warns falsely (-Wrestrict) on `"." + std::string` here.
  std::string tmpName(".");
  tmpName.append(p.filename().string())
      .append(".tmp")
      .append(std::to_string(::getpid()))
      .append("_")
      .append(std::to_string(counter++))
      .append(ext);
  const fs::path tmp = p.parent_path() / tmpName;
  try {
    write(tmp.string());
    std::error_code ec;
    fs::rename(tmp, p, ec);
    if (ec) throw IoError(path + ": cannot rename temporary file: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw IoError(path + ": cannot open for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw IoError(path + ": write failed (disk full?)");
  });
}

}  // namespace vs
