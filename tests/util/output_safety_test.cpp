// Outputs never destroy inputs, multi-file outputs are all-or-nothing, and a process-wide
// cancellation (what Ctrl-C sets) stops Progress and every pending commit without leftovers.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "util/atomic_file.h"
#include "util/cancel.h"
#include "util/error.h"
#include "util/progress.h"

namespace fs = std::filesystem;

namespace {

struct Dir {
  fs::path path;
  explicit Dir(const std::string& name) : path(fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Dir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& n) const { return (path / n).string(); }
  size_t entries() const {
    return static_cast<size_t>(std::distance(fs::directory_iterator(path), fs::directory_iterator()));
  }
};

std::string slurp(const std::string& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Clears the process-wide flag even when an assertion fails.
struct CancelGuard {
  ~CancelGuard() { vs::clearGlobalCancel(); }
};

}  // namespace

TEST(OutputSet, CommitsAllFilesTogether) {
  Dir d("vs_outset_ok");
  vs::OutputSet set;
  set.add(d.file("a.txt"));
  set.add(d.file("b.txt"));
  set.writeBytes(d.file("a.txt"), "alpha");
  EXPECT_FALSE(fs::exists(d.file("a.txt")));  // nothing visible before commit
  set.writeBytes(d.file("b.txt"), "beta");
  set.commit();
  EXPECT_EQ(slurp(d.file("a.txt")), "alpha");
  EXPECT_EQ(slurp(d.file("b.txt")), "beta");
  EXPECT_EQ(d.entries(), 2u);
}

TEST(OutputSet, AFailingMemberLeavesNoOutputAndNoTemporary) {
  Dir d("vs_outset_fail");
  {
    vs::OutputSet set;
    set.writeBytes(d.file("a.txt"), "alpha");
    EXPECT_THROW(set.write(d.file("b.txt"), [](const std::string&) { throw vs::IoError("b.txt: disk full"); }),
                 vs::IoError);
  }  // destroyed without commit
  EXPECT_EQ(d.entries(), 0u);
}

TEST(OutputSet, SameFileTwiceAndMissingFolderAreRefusedWhenAdded) {
  Dir d("vs_outset_dup");
  vs::OutputSet set;
  set.add(d.file("a.txt"));
  EXPECT_THROW(set.add(d.file("./a.txt")), vs::InvalidArgument);
  EXPECT_THROW(set.add(d.file("missing/x.txt")), vs::IoError);
  EXPECT_THROW(set.commit(), vs::IoError);  // added but never written
  EXPECT_EQ(d.entries(), 0u);
}

TEST(Cancellation, GlobalFlagStopsProgressAndCommits) {
  CancelGuard guard;
  Dir d("vs_cancel");
  vs::Progress progress;
  EXPECT_NO_THROW(progress.check());
  vs::OutputSet set;
  set.writeBytes(d.file("a.txt"), "alpha");
  vs::requestGlobalCancel();
  EXPECT_THROW(progress.check(), vs::Cancelled);
  EXPECT_THROW(vs::Progress::none().check(), vs::Cancelled);
  EXPECT_THROW(set.commit(), vs::Cancelled);
  EXPECT_THROW(vs::writeFileAtomically(d.file("b.txt"), "beta"), vs::Cancelled);
  vs::clearGlobalCancel();
  EXPECT_NO_THROW(progress.check());
  EXPECT_FALSE(fs::exists(d.file("a.txt")));
  EXPECT_FALSE(fs::exists(d.file("b.txt")));
  EXPECT_EQ(d.entries(), 1u);  // only the set's private folder, removed with the set
}

TEST(Cancellation, RegisteredTemporariesCanBeUnlinkedFromAHandler) {
  Dir d("vs_cancel_tmp");
  const std::string tmp = d.file(".x.tmp");
  std::ofstream(tmp) << "x";
  const int slot = vs::registerTemporary(tmp.c_str());
  ASSERT_GE(slot, 0);
  EXPECT_EQ(vs::unlinkRegisteredTemporaries(), 1u);
  EXPECT_FALSE(fs::exists(tmp));
  vs::unregisterTemporary(slot);
  EXPECT_EQ(vs::unlinkRegisteredTemporaries(), 0u);
}

TEST(OutputChecks, SameFileByInodeNotBySpelling) {
  Dir d("vs_outchk");
  const std::string in = d.file("in.nii");
  std::ofstream(in) << "data";
  fs::create_symlink(in, d.file("alias.nii"));
  EXPECT_TRUE(vs::sameFile(in, d.file("alias.nii")));
  EXPECT_TRUE(vs::sameFile(in, d.file("../" + d.path.filename().string() + "/in.nii")));
  EXPECT_TRUE(vs::sameFile(d.file("new.json"), d.file("./new.json")));  // neither exists yet
  EXPECT_FALSE(vs::sameFile(in, d.file("new.json")));
  EXPECT_THROW(vs::checkOutputs({in}, {d.file("alias.nii")}), vs::InvalidArgument);
  EXPECT_THROW(vs::checkOutputs({in}, {d.file("t.json"), d.file("./t.json")}), vs::InvalidArgument);
  EXPECT_THROW(vs::checkOutputs({in}, {d.file("nofolder/t.json")}), vs::IoError);
  EXPECT_NO_THROW(vs::checkOutputs({in}, {d.file("t.json"), d.file("t.swc"), ""}));
  EXPECT_EQ(slurp(in), "data");
}

TEST(OutputChecks, ProtectedInputsAreNeverOverwritten) {
  Dir d("vs_outprot");
  const std::string in = d.file("in.txt");
  std::ofstream(in) << "data";
  vs::protectInputs(true);
  vs::noteInputFile(in);
  EXPECT_THROW(vs::writeFileAtomically(d.file("./in.txt"), "overwritten"), vs::IoError);
  vs::protectInputs(false);  // interactive front ends may save over what they opened
  EXPECT_NO_THROW(vs::writeFileAtomically(in, "saved"));
  EXPECT_EQ(slurp(in), "saved");
}

// Outputs that are not regular files (issue 22): a FIFO, a device, a symbolic link to one are
// refused before any work (UsageError, exit 2) and never replaced; a symbolic link to a regular
// file (or a dangling one) is written through: the link stays, its target gets the content.
TEST(OutputChecks, NonRegularOutputsAreRefusedAndNeverReplaced) {
  Dir d("vs_special_out");
  const std::string fifo = d.file("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(vs::checkOutputPath(fifo), vs::UsageError);
  EXPECT_THROW(vs::writeFileAtomically(fifo, "x"), vs::UsageError);
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  const std::string full = d.file("to_full");
  fs::create_symlink("/dev/full", full);
  try {
    vs::writeFileAtomically(full, "x");
    ADD_FAILURE() << "a link to /dev/full was written";
  } catch (const vs::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("character device"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(full)));
  vs::OutputSet set;
  EXPECT_THROW(set.add(fifo), vs::UsageError);
  EXPECT_EQ(d.entries(), 2u);  // nothing else appeared
}

TEST(OutputChecks, SymbolicLinksAreWrittenThroughNotReplaced) {
  Dir d("vs_link_out");
  fs::create_directories(d.path / "real");
  { std::ofstream(d.file("real/target.txt")) << "old"; }
  fs::create_symlink("real/target.txt", d.path / "link.txt");
  vs::writeFileAtomically(d.file("link.txt"), "new");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d.path / "link.txt")));
  EXPECT_EQ(slurp(d.file("real/target.txt")), "new");
  fs::create_symlink("real/made.txt", d.path / "dangling.txt");
  vs::OutputSet set;
  set.writeBytes(d.file("dangling.txt"), "made");
  set.commit();
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d.path / "dangling.txt")));
  EXPECT_EQ(slurp(d.file("real/made.txt")), "made");
  EXPECT_EQ(std::distance(fs::directory_iterator(d.path / "real"), fs::directory_iterator()), 2);
}
