#include <gtest/gtest.h>

#include <stdexcept>

#include "io/atomic_file.hpp"
#include "io/io_error.hpp"
#include "temp_dir.hpp"

namespace adit::io {
namespace {

using test::TempDir;
using test::readAll;

TEST(AtomicFile, WritesExactBytesAndLeavesNoTempFile) {
  TempDir dir;
  const std::string bytes("binary\0data\nwith nul", 20);
  writeFileAtomically(dir.file("out.bin"), bytes);
  EXPECT_EQ(readAll(dir.file("out.bin")), bytes);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.bin"});
}

TEST(AtomicFile, ReplacesAnExistingFile) {
  TempDir dir;
  dir.write("out.txt", "old content that is longer");
  writeFileAtomically(dir.file("out.txt"), std::string("new"));
  EXPECT_EQ(readAll(dir.file("out.txt")), "new");
  EXPECT_EQ(dir.entries().size(), 1u);
}

TEST(AtomicFile, StreamingVariantWritesWhatTheCallbackWrites) {
  TempDir dir;
  writeFileAtomically(dir.file("big.txt"), [](std::ostream& out) {
    for (int i = 0; i < 1000; ++i) out << i << '\n';
  });
  const std::string text = readAll(dir.file("big.txt"));
  EXPECT_EQ(text.substr(0, 4), "0\n1\n");
  EXPECT_EQ(text.substr(text.size() - 4), "999\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"big.txt"});
}

TEST(AtomicFile, FailingWriterKeepsTheOldFileAndRemovesTheTemp) {
  TempDir dir;
  dir.write("keep.txt", "original");
  EXPECT_THROW(writeFileAtomically(dir.file("keep.txt"),
                                   [](std::ostream& out) {
                                     out << "partial";
                                     throw std::logic_error("writer failed");
                                   }),
               std::logic_error);
  EXPECT_EQ(readAll(dir.file("keep.txt")), "original");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicFile, MissingDirectoryThrowsWriteErrorNamingTheFile) {
  TempDir dir;
  const std::string path = dir.file("no/such/dir/out.txt");
  try {
    writeFileAtomically(path, std::string("x"));
    FAIL() << "expected WriteError";
  } catch (const WriteError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace adit::io
