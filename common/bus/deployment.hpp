#pragma once
// The secure deployment's rule for nodes that take commands (docs/security.md, "Deployment: one
// door"): on the air host only the door (aerie-link's air half) may bring a command in, so a node
// that obeys commands must keep its LCM on the host (multicast ttl=0). A deployment is marked
// secure by AERIE_DEPLOYMENT=secure in the nodes' environment (the launchers export it).
#include <optional>
#include <string>

namespace aerie::bus {

// The multicast TTL of an LCM URL ("" = LCM_DEFAULT_URL, else LCM's default, ttl 0); nullopt
// for a URL that is not udpm:// (memq://, file://: nothing reaches it from the network).
std::optional<int> multicast_ttl(const std::string& url);
// AERIE_DEPLOYMENT=secure in the environment.
bool secure_deployment();
// Throws std::runtime_error naming the node, the commands, the URL and the fix when the
// deployment is secure and `url` is reachable from the network (ttl > 0).
void require_host_local_commands(const std::string& node, const std::string& commands, const std::string& url);

}  // namespace aerie::bus
