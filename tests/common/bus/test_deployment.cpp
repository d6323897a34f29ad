// The secure deployment's rule: a node that takes commands refuses a network-facing LCM URL.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/bus/deployment.hpp"

namespace aerie::bus {
namespace {

struct Env {
  explicit Env(const char* deployment) {
    if (deployment)
      setenv("AERIE_DEPLOYMENT", deployment, 1);
    else
      unsetenv("AERIE_DEPLOYMENT");
    unsetenv("LCM_DEFAULT_URL");
  }
  ~Env() {
    unsetenv("AERIE_DEPLOYMENT");
    unsetenv("LCM_DEFAULT_URL");
  }
};

TEST(Deployment, TheTtlOfAUrl) {
  Env env(nullptr);
  EXPECT_EQ(multicast_ttl("udpm://239.255.76.67:7667?ttl=0"), 0);
  EXPECT_EQ(multicast_ttl("udpm://239.255.76.67:7667?recv_buf_size=4194304&ttl=1"), 1);
  EXPECT_EQ(multicast_ttl("udpm://239.255.76.67:7667"), 0);
  EXPECT_EQ(multicast_ttl(""), 0);  // LCM's default
  setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7667?ttl=2", 1);
  EXPECT_EQ(multicast_ttl(""), 2);
  EXPECT_EQ(multicast_ttl("memq://"), std::nullopt);
  EXPECT_EQ(multicast_ttl("file:///tmp/x.lcm?mode=w"), std::nullopt);
  EXPECT_THROW(multicast_ttl("udpm://239.255.76.67:7667?ttl=x"), std::runtime_error);
}

TEST(Deployment, ACommandTakerRefusesANetworkFacingUrlOnlyWhenTheDeploymentIsSecure) {
  {
    Env env(nullptr);  // not marked: libbot2-style LANs keep working
    EXPECT_NO_THROW(require_host_local_commands("aerie-pilot", "PILOT_CMD", "udpm://239.255.76.67:7667?ttl=1"));
  }
  Env env("secure");
  EXPECT_NO_THROW(require_host_local_commands("aerie-pilot", "PILOT_CMD", "udpm://239.255.76.67:7667?ttl=0"));
  EXPECT_NO_THROW(require_host_local_commands("aerie-pilot", "PILOT_CMD", "memq://"));
  try {
    require_host_local_commands("aerie-pilot", "PILOT_CMD", "udpm://239.255.76.67:7667?ttl=1");
    FAIL() << "a network-facing URL was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("aerie-pilot takes PILOT_CMD"), std::string::npos) << what;
    EXPECT_NE(what.find("ttl=1"), std::string::npos) << what;
    EXPECT_NE(what.find("AERIE_DEPLOYMENT=secure"), std::string::npos) << what;
  }
}

TEST(Deployment, ThePilotRefusesToStartOnANetworkFacingUrlInASecureDeployment) {
  const std::string cmd = std::string("AERIE_DEPLOYMENT=secure ") + AERIE_BINARY_DIR +
                          "/bin/aerie-pilot --config " + AERIE_SOURCE_DIR +
                          "/config/pilot.yaml --lcm-url 'udpm://239.255.76.67:7667?ttl=1' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) out += buf;
  const int status = pclose(p);
  EXPECT_EQ(WEXITSTATUS(status), 1) << out;
  EXPECT_NE(out.find("aerie-pilot takes PILOT_CMD"), std::string::npos) << out;
}

}  // namespace
}  // namespace aerie::bus
