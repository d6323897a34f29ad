#include <gtest/gtest.h>

#include "common/util/config.hpp"

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
