#include "common/bus/deployment.hpp"

#include <cstdlib>
#include <stdexcept>

namespace aerie::bus {

std::optional<int> multicast_ttl(const std::string& given) {
  std::string url = given;
  if (url.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    url = env && *env ? env : "udpm://239.255.76.67:7667?ttl=0";
  }
  if (url.rfind("udpm://", 0) != 0) return std::nullopt;
  const size_t q = url.find('?');
  if (q == std::string::npos) return 0;  // LCM's default ttl
  size_t at = url.find("ttl=", q);
  while (at != std::string::npos && url[at - 1] != '?' && url[at - 1] != '&') at = url.find("ttl=", at + 1);
  if (at == std::string::npos) return 0;
  try {
    return std::stoi(url.substr(at + 4));
  } catch (const std::exception&) {
    throw std::runtime_error("LCM URL '" + url + "': ttl is not a number");
  }
}

bool secure_deployment() {
  const char* d = std::getenv("AERIE_DEPLOYMENT");
  return d && std::string(d) == "secure";
}

void require_host_local_commands(const std::string& node, const std::string& commands, const std::string& url) {
  if (!secure_deployment()) return;
  const auto ttl = multicast_ttl(url);
  if (ttl && *ttl > 0)
    throw std::runtime_error(node + " takes " + commands + " on " + (url.empty() ? "the default LCM URL" : url) +
                             " (multicast ttl=" + std::to_string(*ttl) +
                             ", reachable from the network) while the deployment is secure (AERIE_DEPLOYMENT=secure): "
                             "keep LCM on the host (ttl=0) and let commands in through the door, aerie-link "
                             "(docs/security.md)");
}

}  // namespace aerie::bus
