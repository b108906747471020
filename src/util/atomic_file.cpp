#include "util/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <utility>

#include "util/cancel.h"
#include "util/error.h"

namespace fs = std::filesystem;

namespace vs {

namespace {

using FileId = std::pair<dev_t, ino_t>;

bool fileId(const std::string& path, FileId& id) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return false;
  id = {st.st_dev, st.st_ino};
  return true;
}

std::atomic<bool> gProtectInputs{false};
std::mutex gInputsMutex;
std::set<FileId>& inputs() {
  static std::set<FileId> ids;
  return ids;
}

bool isInput(const std::string& path) {
  FileId id;
  if (!gProtectInputs.load() || !fileId(path, id)) return false;
  std::lock_guard<std::mutex> lock(gInputsMutex);
  return inputs().count(id) > 0;
}

std::atomic<unsigned> gCounter{0};

std::string uniqueSuffix() { return std::to_string(::getpid()) + "_" + std::to_string(gCounter++); }

// A cancellation that arrived while a writer ran (ITK does not poll) must not be followed
// by a rename: the command is being stopped.
void throwIfCancelled() {
  if (globalCancelRequested()) throw Cancelled();
}

}  // namespace

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

void protectInputs(bool on) { gProtectInputs.store(on); }

void noteInputFile(const std::string& path) {
  FileId id;
  if (!gProtectInputs.load() || !fileId(path, id)) return;
  std::lock_guard<std::mutex> lock(gInputsMutex);
  inputs().emplace(id.first, id.second);
}

bool sameFile(const std::string& a, const std::string& b) {
  FileId ia, ib;
  const bool ea = fileId(a, ia), eb = fileId(b, ib);
  if (ea && eb) return ia == ib;
  if (ea != eb) return false;  // one exists, the other not: different files
  std::error_code ec;
  const fs::path na = fs::weakly_canonical(fs::absolute(a, ec), ec), nb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return na == nb;
}

std::string resolveOutputTarget(const std::string& path) {
  if (path.empty()) throw IoError("output path is empty");
  fs::path p(path);
  for (int hops = 0;; ++hops) {
    struct stat st;
    if (::lstat(p.c_str(), &st) != 0) return p.string();  // a new file (or a dangling link's target)
    if (S_ISREG(st.st_mode) || S_ISDIR(st.st_mode)) return p.string();
    const std::string via = p.string() == path ? std::string() : " (the symbolic link leads to " + p.string() + ")";
    if (S_ISLNK(st.st_mode)) {
      if (hops >= 40) throw UsageError(path + ": too many levels of symbolic links");
      std::error_code ec;
      const fs::path t = fs::read_symlink(p, ec);
      if (ec) throw IoError(path + ": cannot read the symbolic link: " + ec.message());
      p = t.is_absolute() ? t : p.parent_path() / t;
      continue;
    }
    const char* kind = S_ISCHR(st.st_mode)    ? "a character device"
                       : S_ISBLK(st.st_mode)  ? "a block device"
                       : S_ISFIFO(st.st_mode) ? "a FIFO (named pipe)"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    throw UsageError(path + ": is " + kind + via +
                     "; outputs are only written as regular files, never over a device, FIFO or socket");
  }
}

void checkOutputPath(const std::string& requested) {
  if (requested.empty()) throw IoError("output path is empty");
  // A symbolic link is written through to its target (the link stays); anything that is not
  // a regular file is refused before any work is done.
  const std::string path = resolveOutputTarget(requested);
  fs::path p(path);
  fs::path dir = p.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError(path + ": output directory '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw IoError(path + ": output directory '" + dir.string() + "' is not writable");
  if (fs::is_directory(p, ec)) throw IoError(path + ": is a directory");
  if (isInput(path)) throw IoError(path + ": refusing to overwrite an input of this command with an output");
}

void checkOutputs(const std::vector<std::string>& inputPaths, const std::vector<std::string>& outputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].empty()) continue;
    for (const auto& in : inputPaths)
      if (!in.empty() && sameFile(in, outputs[i]))
        throw InvalidArgument(outputs[i] + ": output is the same file as the input " + in + " (it would be destroyed)");
    for (size_t j = 0; j < i; ++j)
      if (!outputs[j].empty() && sameFile(outputs[j], outputs[i]))
        throw InvalidArgument(outputs[i] + ": the same file is given for two outputs (" + outputs[j] + ")");
  }
  for (const auto& out : outputs)
    if (!out.empty()) checkOutputPath(out);
}

void writeAtomically(const std::string& requested, const std::function<void(const std::string&)>& write) {
  checkOutputPath(requested);
  const std::string path = resolveOutputTarget(requested);
  fs::path p(path);
  const std::string ext = fileExtension(path);
  // Built with append: GCC 12 warns falsely (-Wrestrict) on `"." + std::string` here.
  std::string tmpName(".");
  tmpName.append(p.filename().string()).append(".tmp").append(uniqueSuffix()).append(ext);
  const fs::path tmp = p.parent_path() / tmpName;
  const int slot = registerTemporary(tmp.c_str());
  try {
    write(tmp.string());
    throwIfCancelled();
    std::error_code ec;
    fs::rename(tmp, p, ec);
    if (ec) throw IoError(path + ": cannot rename temporary file: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    unregisterTemporary(slot);
    throw;
  }
  unregisterTemporary(slot);
}

std::string readTextFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw IoError(path + ": cannot open " + what + " (file not found)");
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": cannot open " + what + " (is a directory)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open " + what);
  noteInputFile(path);
  // In blocks, not a byte at a time through istreambuf_iterator (session 45 speedE: 14 instructions a byte, 2 % of
  // the carotid trace's instructions for its 2.7 MB legacy VTK file); the same bytes.
  std::string text;
  if (const auto size = std::filesystem::file_size(path, ec); !ec) text.reserve(static_cast<size_t>(size));
  char block[1 << 16];
  while (in.read(block, sizeof block) || in.gcount() > 0) text.append(block, static_cast<size_t>(in.gcount()));
  if (in.bad()) throw IoError(path + ": read error");
  return text;
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  writeAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw IoError(path + ": cannot open for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw IoError(path + ": write failed (disk full?)");
    std::error_code ec;
    if (fs::file_size(tmp, ec) != bytes.size() || ec) throw IoError(path + ": short write (disk full?)");
  });
}

// ---------------------------------------------------------------- OutputSet
OutputSet::~OutputSet() { discard(); }

void OutputSet::discard() noexcept {
  for (auto& e : entries_) {
    if (!e.tmpDir.empty()) {
      std::error_code ec;
      fs::remove_all(e.tmpDir, ec);
    }
    unregisterTemporary(e.slot);
  }
  entries_.clear();
}

void OutputSet::add(const std::string& path) {
  for (const auto& e : entries_)
    if (sameFile(e.target, path))
      throw InvalidArgument(path + ": the same file is given for two outputs (" + e.target + ")");
  checkOutputPath(path);
  entries_.push_back({path, resolveOutputTarget(path), {}, -1, false});
}

void OutputSet::write(const std::string& path, const std::function<void(const std::string&)>& writer) {
  auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.target == path; });
  if (it == entries_.end()) {
    add(path);
    it = entries_.end() - 1;
  }
  if (it->written) throw IoError(path + ": written twice in one output set");
  const fs::path target(it->resolved);
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const fs::path tmpDir = dir / (".vs_out_" + uniqueSuffix());
  std::error_code ec;
  if (!fs::create_directory(tmpDir, ec)) throw IoError(path + ": cannot create a temporary folder: " + ec.message());
  it->tmpDir = tmpDir.string();
  it->slot = registerTemporary((tmpDir / target.filename()).c_str());
  writer((tmpDir / target.filename()).string());
  throwIfCancelled();
  if (!fs::exists(tmpDir / target.filename(), ec)) throw IoError(path + ": the writer produced no file");
  it->written = true;
}

void OutputSet::writeBytes(const std::string& path, const std::string& bytes) {
  write(path, [&](const std::string& tmp) { writeFileAtomically(tmp, bytes); });
}

void OutputSet::commit() {
  for (const auto& e : entries_)
    if (!e.written) throw IoError(e.target + ": output was never written");
  throwIfCancelled();
  // Data files (detached .raw of .nhdr/.mhd) first, each named file last.
  for (const auto& e : entries_) {
    const fs::path target(e.resolved);
    const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    for (const auto& f : fs::directory_iterator(e.tmpDir, ec)) {
      if (f.path().filename() == target.filename()) continue;
      fs::rename(f.path(), dir / f.path().filename(), ec);
      if (ec) throw IoError(e.target + ": cannot move data file into place: " + ec.message());
    }
  }
  for (auto& e : entries_) {
    const fs::path target(e.resolved);
    std::error_code ec;
    fs::rename(fs::path(e.tmpDir) / target.filename(), target, ec);
    if (ec) throw IoError(e.target + ": cannot move the output into place: " + ec.message());
  }
  discard();
}

}  // namespace vs
