#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>

#include "common/camera/calibration_io.hpp"
#include "common/flc/flc_io.hpp"
#include "common/util/config.hpp"
#include "tests/support/test_support.hpp"

using aerie::util::Config;

TEST(Config, DottedKeysDefaultsAndErrors) {
  const auto c = Config::parse("a:\n  b: 3\n  name: x\nlist: [1, 2]\n", "inline.yaml");
  EXPECT_EQ(c.get<int>("a.b", 0), 3);
  EXPECT_EQ(c.get<int>("a.missing", 9), 9);
  EXPECT_EQ(c.get<std::vector<int>>("list", {}), (std::vector<int>{1, 2}));
  EXPECT_EQ(c.section("a").get<std::string>("name", ""), "x");
  try {
    c.get<int>("a.name", 0);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("inline.yaml: key 'a.name'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(c.require<int>("nope"), std::runtime_error);
  EXPECT_THROW(Config::load("/nonexistent.yaml"), std::runtime_error);
  EXPECT_THROW(Config::parse("a: [1, 2", "broken.yaml"), std::runtime_error);
}

namespace {
// The message of the std::runtime_error that f throws ("" when it throws none).
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, RefusesAFileThatIsNotRegular) {
  // A FIFO would block the node at start-up: refused before it is opened.
  const auto dir = aerie::test::scratch_dir("fifo");
  const auto fifo = dir / "config.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string e = error_of([&] { Config::load(fifo.string()); });
  EXPECT_NE(e.find("config.yaml: a config file must be a regular file"), std::string::npos) << e;
  EXPECT_NE(error_of([&] { Config::load(dir.string()); }).find("regular file"), std::string::npos);
  // The same for the other files a user names: a controller and a calibration.
  EXPECT_NE(error_of([&] { aerie::flc::load_controller(fifo.string()); }).find("a controller file must be a regular file"),
            std::string::npos);
  EXPECT_NE(error_of([&] { aerie::camera::read_kitti_stereo(fifo.string(), 376, 240); })
                .find("a calibration file must be a regular file"),
            std::string::npos);
  EXPECT_NE(error_of([&] { aerie::camera::read_euroc_camera(fifo.string()); }).find("regular file"), std::string::npos);
}

TEST(Config, RefusesDuplicateKeysNamingBothLines) {
  const std::string e = error_of([] { Config::parse("a:\n  b: 1\n  c: 2\n  b: 3\n", "dup.yaml"); });
  EXPECT_NE(e.find("dup.yaml: duplicate key 'a.b' (line 2 and line 4)"), std::string::npos) << e;
  const auto dir = aerie::test::scratch_dir("dup");
  std::ofstream(dir / "d.yaml") << "x: 1\nx: 2\n";
  EXPECT_NE(error_of([&] { Config::load((dir / "d.yaml").string()); }).find("duplicate key 'x' (line 1 and line 2)"),
            std::string::npos);
  EXPECT_EQ(error_of([] { Config::parse("a: 1\nb:\n  a: 2\n"); }), "");  // the same name in two maps is fine
}

TEST(Config, CheckKeysRefusesUnknownKeysScalarsForSectionsAndLists) {
  const std::vector<std::string> known{"rate", "limits.max", "limits.min", "open.*"};
  EXPECT_EQ(error_of([&] { Config::parse("rate: 1\nlimits:\n  max: 2\nopen: {anything: [1]}\n").check_keys(known); }), "");
  EXPECT_EQ(error_of([&] { Config::parse("").check_keys(known); }), "");  // empty file: defaults
  std::string e = error_of([&] { Config::parse("rate: 1\nlimits:\n  mx: 2\n", "k.yaml").check_keys(known); });
  EXPECT_NE(e.find("k.yaml: unknown key 'limits.mx' (line 3)"), std::string::npos) << e;
  e = error_of([&] { Config::parse("rate: 1\nlimits: 5\n", "k.yaml").check_keys(known); });
  EXPECT_NE(e.find("k.yaml: 'limits' is a section of keys, not a value (line 2)"), std::string::npos) << e;
  e = error_of([&] { Config::parse("limits: [1, 2]\n", "k.yaml").check_keys(known); });
  EXPECT_NE(e.find("'limits' is a section of keys, not a list (line 1)"), std::string::npos) << e;
  e = error_of([&] { Config::parse("- rate: 1\n- limits: {}\n", "k.yaml").check_keys(known); });
  EXPECT_NE(e.find("k.yaml: expected a map of keys, not a list (line 1)"), std::string::npos) << e;
  e = error_of([&] { Config::parse("[1, 2]: 3\n", "k.yaml").check_keys(known); });
  EXPECT_NE(e.find("is not a name"), std::string::npos) << e;
}

TEST(Config, GetInRefusesValuesOutsideTheRange) {
  const auto c = Config::parse("fps: 1e308\nnan: .nan\nok: 20\nneg: -1\n", "r.yaml");
  EXPECT_DOUBLE_EQ(c.get_in("ok", 5.0, 0.01, 1000.0), 20.0);
  EXPECT_DOUBLE_EQ(c.get_in("absent", 5.0, 0.01, 1000.0), 5.0);
  std::string e = error_of([&] { c.get_in("fps", 5.0, 0.01, 1000.0); });
  EXPECT_NE(e.find("r.yaml: key 'fps' = 1e+308 is outside its valid range [0.01, 1000] (line 1)"), std::string::npos) << e;
  EXPECT_NE(error_of([&] { c.get_in("nan", 5.0, 0.0, 1.0); }).find("'nan' = nan"), std::string::npos);
  EXPECT_NE(error_of([&] { c.get_in<int64_t>("neg", 1, 1, 100); }).find("'neg' = -1 is outside"), std::string::npos);
}

TEST(Config, ErrorsNameTheLineOfANestedKey) {
  const auto c = Config::parse("a:\n  b:\n    c: 1e308\n    d: text\n", "n.yaml");
  std::string e = error_of([&] { c.get_in("a.b.c", 1.0, 0.0, 10.0); });
  EXPECT_NE(e.find("(line 3)"), std::string::npos) << e;
  e = error_of([&] { c.section("a").section("b").get<int>("d", 0); });
  EXPECT_NE(e.find("(line 4)"), std::string::npos) << e;
  EXPECT_FALSE(c.has("a.x"));  // a lookup inserts nothing
  EXPECT_EQ(error_of([&] { c.check_keys({"a.b.c", "a.b.d"}); }), "");
}

// A copy shares the document of the Config it was copied from; assigning another Config to
// the copy must rebind it, not write through into the shared document (yaml-cpp's own
// Node::operator= does: every copy of the original, in any thread, would change with it).
// aerie-linkstudy --jobs 2 crashed in yaml-cpp that way: each flight assigned new node options
// to its copy of the study's, and the two threads rewrote the study's document at once.
TEST(Config, AssigningToACopyLeavesTheOriginalAsItWas) {
  const Config original = Config::parse("x: 1\nsection: {y: 2}\n", "original.yaml");
  Config copy = original;
  copy = Config::parse("x: 5\n", "other.yaml");
  EXPECT_EQ(copy.get<int>("x", 0), 5);
  EXPECT_EQ(copy.origin(), "other.yaml");
  EXPECT_EQ(original.get<int>("x", 0), 1);
  EXPECT_EQ(original.get<int>("section.y", 0), 2);
  Config part = original.section("section");
  part = Config();
  EXPECT_FALSE(part.has("y"));
  EXPECT_EQ(original.get<int>("section.y", 0), 2);
  copy = original;  // and back: the same document again
  EXPECT_EQ(copy.get<int>("section.y", 0), 2);
}
