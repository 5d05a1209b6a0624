#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

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

// A named pipe (like /dev/null or /dev/stdout: not a regular file) is written in place and stays a pipe; a
// rename over it would have replaced it with a regular file.
TEST(AtomicFile, APipeIsWrittenInPlaceNotReplaced) {
  TempDir dir;
  const std::string fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_TRUE(writesInPlace(fifo));
  EXPECT_FALSE(writesInPlace(dir.file("absent")));
  // The reading end first (non-blocking, so a wrong rename fails the test instead of hanging it).
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  writeFileAtomically(fifo, std::string("through the pipe"));
  char buf[64] = {};
  const ssize_t got = ::read(fd, buf, sizeof buf);
  ::close(fd);
  EXPECT_EQ(std::string(buf, got > 0 ? static_cast<std::size_t>(got) : 0), "through the pipe");
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"pipe"});
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
