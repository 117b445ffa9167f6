// bimart object make / info / list through the real program.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>

namespace {

struct CliRun {
  int code;
  std::string output;  // stdout and stderr
};

CliRun bimart(const std::string& args) {
  const std::string cmd = std::string(BIMART_CLI) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(ObjectCli, MakeThenInfo) {
  const auto dir = std::filesystem::temp_directory_path() / "bimart_object_cli_phone";
  std::filesystem::remove_all(dir);
  const CliRun made = bimart("object make --category phone --seed 2 --out " + dir.string());
  ASSERT_EQ(made.code, 0) << made.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "object.yaml"));
  const CliRun info = bimart("object info " + dir.string());
  ASSERT_EQ(info.code, 0) << info.output;
  EXPECT_NE(info.output.find("name        phone_2"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("1380 vertices"), std::string::npos) << info.output;
  EXPECT_EQ(info.output.find("OPEN"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("[0.0, 165.0] deg"), std::string::npos) << info.output;
  std::filesystem::remove_all(dir);
}

TEST(ObjectCli, UnknownCategoryAndList) {
  const CliRun bad = bimart("object make --category fone --out /tmp/bimart_object_cli_never");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.output.find("did you mean 'phone'"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists("/tmp/bimart_object_cli_never"));
  const CliRun list = bimart("object list");
  EXPECT_EQ(list.code, 0);
  EXPECT_NE(list.output.find("| `scissors` |"), std::string::npos) << list.output;
}

}  // namespace
