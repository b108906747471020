// Atomic output: write to a temporary file beside the target, then rename, so a
// failure (or a crash) never leaves a half-written output under the final name.
#pragma once

#include <functional>
#include <string>

namespace vs {

// Checks that the directory of `path` exists and is writable; throws IoError naming the path.
void checkOutputPath(const std::string& path);

// Calls write(tmpPath) and renames tmpPath to path on success. On any exception the
// temporary is removed and the exception propagates. The temporary keeps the target's
// extension (e.g. "out.nii.gz" -> ".out.nii.gz.tmp123.nii.gz") so writers that choose
// a format from the extension still work.
void writeAtomically(const std::string& path, const std::function<void(const std::string& tmpPath)>& write);

// Convenience: atomically writes a whole text or binary buffer.
void writeFileAtomically(const std::string& path, const std::string& bytes);

// The lower-case extension of a path including double extensions ".nii.gz", ".tar.gz".
std::string fileExtension(const std::string& path);

}  // namespace vs
