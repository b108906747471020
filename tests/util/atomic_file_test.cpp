#include "util/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace fs = std::filesystem;

TEST(AtomicFile, WritesAndLeavesNoTemporary) {
  const fs::path dir = fs::temp_directory_path() / "vs_atomic_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "out.txt").string();
  vs::writeFileAtomically(path, "hello");
  std::ifstream in(path);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "hello");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailedWriteLeavesNothing) {
  const fs::path dir = fs::temp_directory_path() / "vs_atomic_fail";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "out.nii.gz").string();
  EXPECT_THROW(vs::writeAtomically(path,
                                   [](const std::string& tmp) {
                                     std::ofstream(tmp) << "partial";
                                     EXPECT_EQ(vs::fileExtension(tmp), ".nii.gz");
                                     throw vs::IoError("simulated failure");
                                   }),
               vs::IoError);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingDirectoryIsAnIoError) {
  EXPECT_THROW(vs::writeFileAtomically("/nonexistent_dir_vs/x.txt", "x"), vs::IoError);
}

TEST(AtomicFile, Extensions) {
  EXPECT_EQ(vs::fileExtension("a/b.NII.GZ"), ".nii.gz");
  EXPECT_EQ(vs::fileExtension("a.mha"), ".mha");
  EXPECT_EQ(vs::fileExtension("noext"), "");
}

// readTextFile: the whole file, binary bytes included; a missing file or a folder is an IoError
// naming the path and what was expected.
TEST(AtomicFile, ReadTextFileReadsAllAndNamesWhatFailed) {
  const fs::path dir = fs::temp_directory_path() / "vs_read_text_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string bytes("{\"a\": 1}\n\0\xff tail", 15);
  const std::string path = (dir / "doc.json").string();
  vs::writeFileAtomically(path, bytes);
  EXPECT_EQ(vs::readTextFile(path, "the document"), bytes);
  auto message = [](const std::string& p) {
    try {
      vs::readTextFile(p, "the document");
    } catch (const vs::IoError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string missing = message((dir / "none.json").string());
  EXPECT_NE(missing.find("none.json: cannot open the document (file not found)"), std::string::npos) << missing;
  const std::string folder = message(dir.string());
  EXPECT_NE(folder.find("cannot open the document (is a directory)"), std::string::npos) << folder;
  fs::remove_all(dir);
}
