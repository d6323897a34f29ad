// aerie-keys (tools/keys), run as an operator would: generate, fingerprint, rotate, refusals,
// and the key's bytes never in its output.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/seal/keys.hpp"
#include "tests/support/test_support.hpp"

namespace {

namespace fs = std::filesystem;
using aerie::seal::fingerprint;
using aerie::seal::load_key;

const std::string kTool = AERIE_BINARY_DIR "/bin/aerie-keys";

// stdout and stderr together.
using aerie::test::ToolRun;
ToolRun run(const std::string& args) { return aerie::test::run_tool("'" + kTool + "' " + args + " 2>&1"); }

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

unsigned mode_of(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 0777) : 0;
}

// The key's bytes in any form a careless program might print them: raw, hex, HEX.
void expect_not_leaked(const std::string& output, const std::string& key) {
  ASSERT_EQ(key.size(), 32u);
  EXPECT_EQ(output.find(key), std::string::npos) << "the raw key is in the output";
  std::string hex, HEX;
  char b[3];
  for (const unsigned char c : key) {
    std::snprintf(b, sizeof b, "%02x", c);
    hex += b;
    std::snprintf(b, sizeof b, "%02X", c);
    HEX += b;
  }
  // Any 8 consecutive key bytes, hex-encoded (the fingerprint is a hash, not key bytes).
  for (size_t i = 0; i + 16 <= hex.size(); i += 2) {
    EXPECT_EQ(output.find(hex.substr(i, 16)), std::string::npos) << "key bytes (hex) in the output";
    EXPECT_EQ(output.find(HEX.substr(i, 16)), std::string::npos) << "key bytes (HEX) in the output";
  }
}

class AerieKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kTool)) << kTool << " is not built";
    dir_ = fs::temp_directory_path() / ("aerie_test_keys_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(AerieKeys, GenerateThenFingerprintIsStable) {
  const std::string key = path("mission.key");
  const ToolRun g = run("generate --out '" + key + "'");
  ASSERT_EQ(g.rc, 0) << g.out;
  EXPECT_EQ(mode_of(key), 0600u);
  EXPECT_EQ(fs::file_size(key), 32u);
  const std::string fp = fingerprint(load_key(key));
  EXPECT_NE(g.out.find(fp), std::string::npos) << g.out;
  for (int i = 0; i < 3; ++i) {
    const ToolRun f = run("fingerprint '" + key + "'");
    ASSERT_EQ(f.rc, 0) << f.out;
    EXPECT_EQ(f.out, fp + "\n");
  }
  expect_not_leaked(g.out, file_bytes(key));
}

TEST_F(AerieKeys, GenerateRefusesToOverwriteWithoutForce) {
  const std::string key = path("mission.key");
  ASSERT_EQ(run("generate --out '" + key + "'").rc, 0);
  const std::string before = file_bytes(key);
  const ToolRun again = run("generate --out '" + key + "'");
  EXPECT_EQ(again.rc, 1);
  EXPECT_NE(again.out.find(key), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("exists"), std::string::npos) << again.out;
  EXPECT_EQ(file_bytes(key), before);
  const ToolRun forced = run("generate --force --out '" + key + "'");
  EXPECT_EQ(forced.rc, 0) << forced.out;
  EXPECT_NE(file_bytes(key), before);
  EXPECT_EQ(mode_of(key), 0600u);
}

TEST_F(AerieKeys, RotateKeepsTheOldKey) {
  const std::string key = path("mission.key");
  ASSERT_EQ(run("generate --out '" + key + "'").rc, 0);
  const std::string old_bytes = file_bytes(key);
  const std::string old_fp = fingerprint(load_key(key));
  const ToolRun r = run("rotate '" + key + "'");
  ASSERT_EQ(r.rc, 0) << r.out;
  EXPECT_EQ(file_bytes(key + ".old"), old_bytes);
  EXPECT_EQ(mode_of(key + ".old"), 0600u);
  EXPECT_EQ(mode_of(key), 0600u);
  const std::string new_bytes = file_bytes(key);
  EXPECT_NE(new_bytes, old_bytes);
  const std::string new_fp = fingerprint(load_key(key));
  EXPECT_NE(r.out.find("old fingerprint " + old_fp), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("new fingerprint " + new_fp), std::string::npos) << r.out;
  expect_not_leaked(r.out, old_bytes);
  expect_not_leaked(r.out, new_bytes);
  // A second rotation would lose FILE.old: refused without --force, nothing changed.
  const ToolRun again = run("rotate '" + key + "'");
  EXPECT_EQ(again.rc, 1) << again.out;
  EXPECT_NE(again.out.find(key + ".old"), std::string::npos) << again.out;
  EXPECT_EQ(file_bytes(key), new_bytes);
  EXPECT_EQ(file_bytes(key + ".old"), old_bytes);
  const ToolRun forced = run("rotate --force '" + key + "'");
  EXPECT_EQ(forced.rc, 0) << forced.out;
  EXPECT_EQ(file_bytes(key + ".old"), new_bytes);
}

TEST_F(AerieKeys, RefusesAKeyReadableByOthers) {
  const std::string key = path("open.key");
  ASSERT_EQ(run("generate --out '" + key + "'").rc, 0);
  ASSERT_EQ(::chmod(key.c_str(), 0644), 0);
  for (const std::string sub : {"fingerprint", "rotate"}) {
    const ToolRun r = run(sub + " '" + key + "'");
    EXPECT_EQ(r.rc, 1) << sub;
    EXPECT_NE(r.out.find(key), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("0644"), std::string::npos) << r.out;
    expect_not_leaked(r.out, file_bytes(key));
  }
  EXPECT_FALSE(fs::exists(key + ".old"));
}

TEST_F(AerieKeys, RefusesAWrongSizedFile) {
  const std::string key = path("short.key");
  { std::ofstream(key, std::ios::binary) << std::string(16, 'k'); }
  ASSERT_EQ(::chmod(key.c_str(), 0600), 0);
  const ToolRun r = run("fingerprint '" + key + "'");
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.out.find("16 bytes, expected 32"), std::string::npos) << r.out;
  const ToolRun missing = run("fingerprint '" + path("none") + "'");
  EXPECT_EQ(missing.rc, 1);
  EXPECT_NE(missing.out.find(path("none")), std::string::npos) << missing.out;
}

TEST_F(AerieKeys, HelpOnEverySubcommandAndWrongOptions) {
  for (const std::string sub : {"generate", "fingerprint", "rotate"}) {
    const ToolRun h = run(sub + " --help");
    EXPECT_EQ(h.rc, 0) << sub;
    EXPECT_NE(h.out.find("Usage"), std::string::npos) << h.out;
    EXPECT_GT(h.out.size(), 120u) << h.out;  // a description, not only a usage line
  }
  const ToolRun top = run("--help");
  EXPECT_EQ(top.rc, 0);
  EXPECT_NE(top.out.find("rotate"), std::string::npos) << top.out;
  // CLI11's codes (neither 0 nor the runtime error's 1).
  const ToolRun none = run("");
  EXPECT_NE(none.rc, 0);
  EXPECT_NE(none.rc, 1);
  const ToolRun bad = run("generate --bogus");
  EXPECT_NE(bad.rc, 0);
  EXPECT_NE(bad.rc, 1);
  const ToolRun missing = run("generate");
  EXPECT_NE(missing.rc, 0);
  EXPECT_NE(missing.rc, 1);
  EXPECT_NE(missing.out.find("--out"), std::string::npos) << missing.out;
}

}  // namespace
