// Atomic output: write to a temporary beside the target, then rename, so a failure (or a
// crash, or Ctrl-C) never leaves a half-written output under the final name.
// Outputs never destroy inputs: every file a reader opened is remembered by device and
// inode, and an output that is the same file (whatever the spelling of its path: links,
// "./", "..") is refused, as is an output that is the same file as an earlier output.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace vs {

// What writing to `path` replaces: `path` itself, or, for a symbolic link, its final target
// (outputs are written through a link, never over it). Throws UsageError (CLI exit 2) if that
// exists and is not a regular file or folder: a device (/dev/null, /dev/full), FIFO or socket
// is never replaced by a regular file.
std::string resolveOutputTarget(const std::string& path);

// Checks that the directory of `path` (of a symlink's target) exists and is writable, that
// `path` is not a directory, not a device/FIFO/socket (UsageError) and not a file this
// process read as an input; throws IoError naming the path.
void checkOutputPath(const std::string& path);

// Remembers `path` (an existing file or folder) as an input of this process; readers call it.
// Only while protectInputs(true) (the one-shot CLI turns it on; an interactive front end that
// saves over the file it opened leaves it off).
void protectInputs(bool on);
void noteInputFile(const std::string& path);
// True if `a` and `b` name the same existing file (device and inode), or, when one does not
// exist yet, the same normalised absolute path.
bool sameFile(const std::string& a, const std::string& b);
// Before computing: throws InvalidArgument if an output is one of the inputs or two outputs are
// the same file; then checkOutputPath on each output. Empty strings are ignored.
void checkOutputs(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs);

// Calls write(tmpPath) and renames tmpPath to path on success. On any exception, or when a
// cancellation (Ctrl-C) arrived meanwhile, the temporary is removed and an exception
// propagates (vs::Cancelled for the latter). The temporary keeps the target's extension
// (e.g. "out.nii.gz" -> ".out.nii.gz.tmp123_0.nii.gz") so writers that choose a format from
// the extension still work.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tmpPath)>& write);

// Convenience: atomically writes a whole text or binary buffer; a short write is an IoError.
void writeFileAtomically(const std::string& path, const std::string& bytes);

// The whole of a file read as one buffer (the one home of "read a text file": JSON documents,
// headers, sessions, transfer functions). IoError "<path>: cannot open <what>" (with "(file not
// found)" or "(is a directory)" where that is why) or "<path>: read error"; the file is noted as an input
// (noteInputFile) so no output of the same run may replace it.
std::string readTextFile(const std::string& path, const std::string& what = "file");

// All-or-nothing multi-file output: every file is written into a private temporary folder
// beside its target; commit() moves them all into place once all were written. Destroyed
// without commit (an exception, a cancellation), it removes every temporary and leaves no
// output. Paths are checked when added, i.e. before the work that produces them.
class OutputSet {
 public:
  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet();

  // Checks `path` (see checkOutputPath; not already in the set). Call before computing.
  void add(const std::string& path);
  // Writes the file registered as `path` (added now if it was not): write(tmpPath) must
  // create tmpPath, which has the target's file name (detached .nhdr/.mhd data files may sit
  // beside it and move with it).
  void write(const std::string& path, const std::function<void(const std::string& tmpPath)>& writer);
  void writeBytes(const std::string& path, const std::string& bytes);
  // Moves every written file into place (throws Cancelled, keeping nothing, if a cancellation
  // arrived). Files added but never written are an IoError.
  void commit();

 private:
  struct Entry {
    std::string target, resolved, tmpDir;  // resolved: the file written (a symlink's target)
    int slot = -1;
    bool written = false;
  };
  std::vector<Entry> entries_;
  void discard() noexcept;
};

// The lower-case extension of a path including double extensions ".nii.gz", ".tar.gz".
std::string fileExtension(const std::string& path);

}  // namespace vs
