#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/util/atomic_file.h"
#include "core/util/error.h"

namespace fs = std::filesystem;

TEST(AtomicFile, WritesCreatesFoldersAndLeavesNoTemporary) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_atomic_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path file = dir / "a" / "b.txt";
  bimart::write_file_atomically(file.string(), [](std::ostream& o) { o << "hello"; });
  std::ifstream in(file);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "hello");
  EXPECT_EQ(std::distance(fs::directory_iterator(file.parent_path()), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailureKeepsTheOldFile) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_atomic2_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path file = dir / "out.txt";
  bimart::write_file_atomically(file.string(), [](std::ostream& o) { o << "old"; });
  EXPECT_THROW(bimart::write_file_atomically(file.string(),
                                             [](std::ostream& o) {
                                               o << "half";
                                               throw bimart::Error("disk full");
                                             }),
               bimart::Error);
  std::ifstream in(file);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}
