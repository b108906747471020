// Before a command computes anything: its output paths must be writable, distinct from each
// other and from every input (same file by device and inode, not by spelling), so that
// `info X --json X` or `trace --out t.json --json t.json` fail at once instead of destroying
// a file after minutes of work. Which options are outputs is listed per command in
// output_guard.cpp (a new command with outputs adds one line there).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace vs::cli {

// Throws vs::UsageError (output equals an input or another output) or vs::IoError
// (output folder missing or not writable).
void checkCommandOutputs(const std::string& command, const CLI::App& sub);

}  // namespace vs::cli
