#include "procman/orders_auth.hpp"

#include <sodium.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "common/bus/wire.hpp"
#include "common/util/key_file.hpp"

namespace aerie::procman {
namespace {

static_assert(crypto_auth_hmacsha512256_BYTES == kSealedOrdersTag);
static_assert(crypto_auth_hmacsha512256_KEYBYTES == seal::SecretKey::kSize);
constexpr char kKdfContext[crypto_kdf_CONTEXTBYTES + 1] = "aeriepmd";
constexpr uint64_t kOrdersSubkeyId = 1;
constexpr const char* kStateHeader = "# aerie-deputy order counters v1";

void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
void put_u64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(p[i]) << (8 * i);
  return v;
}
uint64_t get_u64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<uint64_t>(p[i]) << (8 * i);
  return v;
}

std::string who(uint32_t sender, const std::string& name) {
  if (name.empty()) return "sheriff id " + std::to_string(sender);  // pinned, not heard yet
  return "sheriff '" + name + "' (id " + std::to_string(sender) + ")";
}

std::string seconds(double s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f", s);
  return buf;
}

}  // namespace

seal::SecretKey derive_orders_key(const seal::SecretKey& mission_key) {
  seal::init_sodium();
  seal::SecretKey k;
  crypto_kdf_derive_from_key(k.data(), k.size(), kOrdersSubkeyId, kKdfContext, mission_key.data());
  return k;
}

const char* to_string(OrdersRefusal r) {
  switch (r) {
    case OrdersRefusal::None: return "accepted";
    case OrdersRefusal::Unauthenticated: return "unauthenticated (plain PMD_ORDERS2)";
    case OrdersRefusal::Malformed: return "malformed";
    case OrdersRefusal::AuthFailed: return "authentication failed";
    case OrdersRefusal::TooOld: return "too old";
    case OrdersRefusal::FromFuture: return "from the future";
    case OrdersRefusal::Replayed: return "replayed";
    case OrdersRefusal::OtherSheriff: return "from another sheriff";
    default: return "?";
  }
}

const char* counter_name(OrdersRefusal r) {
  switch (r) {
    case OrdersRefusal::None: return "orders_accepted";
    case OrdersRefusal::Unauthenticated: return "orders_unauthenticated";
    case OrdersRefusal::Malformed: return "orders_malformed";
    case OrdersRefusal::AuthFailed: return "orders_auth_failed";
    case OrdersRefusal::TooOld: return "orders_too_old";
    case OrdersRefusal::FromFuture: return "orders_from_future";
    case OrdersRefusal::Replayed: return "orders_replayed";
    case OrdersRefusal::OtherSheriff: return "orders_other_sheriff";
    default: return "orders_unknown";
  }
}

// --- signing ----------------------------------------------------------------------------------
OrdersSigner::OrdersSigner(const seal::SecretKey& mission_key, uint32_t sender)
    : key_(derive_orders_key(mission_key)), sender_(sender) {
  if (sender == 0) throw std::invalid_argument("procman orders signer: sender id must not be 0");
}

std::vector<uint8_t> OrdersSigner::sign(const bot_procman::orders2_t& orders, int64_t now_utime, bool leaving) {
  // MAVLink 2 signing's rule: the counter is a timestamp that must rise.
  const uint64_t clock = now_utime > 0 ? static_cast<uint64_t>(now_utime) : 0;
  counter_ = std::max(counter_ + 1, clock);
  return sign_with_counter(orders, counter_, leaving);
}

std::vector<uint8_t> OrdersSigner::sign_with_counter(const bot_procman::orders2_t& orders, uint64_t counter,
                                                     bool leaving) const {
  const int body = orders.getEncodedSize();
  if (body < 0 || static_cast<size_t>(body) > kMaxSealedOrders - kSealedOrdersHeader - kSealedOrdersTag)
    throw std::invalid_argument("procman orders signer: orders of " + std::to_string(body) + " bytes are too large");
  std::vector<uint8_t> out(kSealedOrdersHeader + static_cast<size_t>(body) + kSealedOrdersTag, 0);
  out[0] = kSealedOrdersMagic;
  out[1] = kSealedOrdersVersion;
  out[2] = leaving ? kSealedOrdersLeaving : 0;
  put_u32(out.data() + 4, sender_);
  put_u64(out.data() + 8, counter);
  if (orders.encode(out.data() + kSealedOrdersHeader, 0, body) != body)
    throw std::invalid_argument("procman orders signer: orders2_t did not encode");
  const size_t n = out.size() - kSealedOrdersTag;
  crypto_auth_hmacsha512256(out.data() + n, out.data(), n, key_.data());
  return out;
}

OrdersRefusal verify_sealed_orders(const seal::SecretKey& orders_key, std::span<const uint8_t> bytes,
                                   VerifiedOrders& out, std::string* why) {
  auto fail = [&](OrdersRefusal r, std::string w) {
    if (why) *why = std::move(w);
    return r;
  };
  if (bytes.size() < kSealedOrdersHeader + 8 + kSealedOrdersTag)
    return fail(OrdersRefusal::Malformed, std::to_string(bytes.size()) + " bytes, shorter than a sealed order");
  if (bytes.size() > kMaxSealedOrders)
    return fail(OrdersRefusal::Malformed, std::to_string(bytes.size()) + " bytes, longer than a sealed order may be");
  if (bytes[0] != kSealedOrdersMagic || bytes[1] != kSealedOrdersVersion || (bytes[2] & ~kSealedOrdersLeaving) != 0 ||
      bytes[3] != 0)
    return fail(OrdersRefusal::Malformed, "not a sealed order of version 1 (magic, version, flags or reserved byte)");
  const size_t n = bytes.size() - kSealedOrdersTag;
  // Constant-time comparison (crypto_auth_verify), before anything of the body is trusted.
  if (crypto_auth_hmacsha512256_verify(bytes.data() + n, bytes.data(), n, orders_key.data()) != 0)
    return fail(OrdersRefusal::AuthFailed, "the tag does not verify (another mission key, or a tampered message)");
  out.sender = get_u32(bytes.data() + 4);
  out.counter = get_u64(bytes.data() + 8);
  out.leaving = (bytes[2] & kSealedOrdersLeaving) != 0;
  if (out.sender == 0) return fail(OrdersRefusal::Malformed, "sender id 0");
  std::string decode_error;
  out.orders = bot_procman::orders2_t{};
  if (!bus::decode_bounded(bytes.data() + kSealedOrdersHeader, n - kSealedOrdersHeader, out.orders, &decode_error))
    return fail(OrdersRefusal::Malformed, decode_error);
  return OrdersRefusal::None;
}

// --- the deputy's gate ------------------------------------------------------------------------
void GateOptions::validate() const {
  if (!(window_s > 0) || !std::isfinite(window_s))
    throw std::invalid_argument("procman gate: window_s must be a positive number of seconds");
  if (!(handover_s >= 0) || !std::isfinite(handover_s))
    throw std::invalid_argument("procman gate: handover_s must be >= 0 seconds");
  if (!(conflict_hold_s >= 0) || !std::isfinite(conflict_hold_s))
    throw std::invalid_argument("procman gate: conflict_hold_s must be >= 0 seconds");
  if (max_senders == 0) throw std::invalid_argument("procman gate: max_senders must be at least 1");
}

OrdersGate::OrdersGate(const seal::SecretKey& mission_key, std::string host, GateOptions options)
    : key_(derive_orders_key(mission_key)),
      host_(std::move(host)),
      options_(std::move(options)),
      fingerprint_(seal::fingerprint(mission_key)) {
  options_.validate();
  follow_ = options_.follow_sheriff;
  load_state();
}

GateVerdict OrdersGate::refuse(GateVerdict v, OrdersRefusal r, std::string why, const std::string& from) {
  v.refusal = r;
  v.why = std::move(why);
  ++refused_[static_cast<size_t>(r)];
  // Logged once per reason and sender; bounded, so a flood of made-up senders cannot grow it.
  const auto key = std::make_pair(r, from);
  if (!logged_.count(key) && logged_.size() < 256) {
    logged_.insert(key);
    v.first = true;
  }
  return v;
}

GateVerdict OrdersGate::refuse_plain(const bot_procman::orders2_t& orders) {
  GateVerdict v;
  return refuse(std::move(v), OrdersRefusal::Unauthenticated,
                "refusing plain PMD_ORDERS2 from sheriff '" + orders.sheriff_name + "' for deputy '" + orders.host +
                    "': this deputy is keyed and takes orders only on PMD_ORDERS2_SEALED with a valid tag",
                "name:" + orders.sheriff_name);
}

GateVerdict OrdersGate::check(std::span<const uint8_t> bytes, int64_t now_utime, int64_t now_ms) {
  GateVerdict v;
  VerifiedOrders in;
  std::string why;
  const OrdersRefusal r = verify_sealed_orders(key_, bytes, in, &why);
  if (r != OrdersRefusal::None) {
    // Unauthenticated bytes: the sender id they claim is only a hint for the log.
    const uint32_t claimed = bytes.size() >= 8 ? get_u32(bytes.data() + 4) : 0;
    return refuse(std::move(v), r,
                  "refusing sealed orders (" + std::string(to_string(r)) + ", claimed sender id " +
                      std::to_string(claimed) + "): " + why,
                  "claimed:" + std::to_string(claimed));
  }
  v.sender = in.sender;
  v.counter = in.counter;
  if (in.orders.host != host_) {
    v.other_host = true;
    return v;
  }
  const std::string from = who(in.sender, in.orders.sheriff_name);
  const std::string id = "id:" + std::to_string(in.sender);
  // In double: the stamp is authenticated but may still be anything (INT64_MIN).
  const double age_s = (static_cast<double>(now_utime) - static_cast<double>(in.orders.utime)) * 1e-6;
  if (age_s > options_.window_s)
    return refuse(std::move(v), OrdersRefusal::TooOld,
                  "refusing orders from " + from + ": they are " + seconds(age_s) + " s old (limit " +
                      seconds(options_.window_s) + " s). Check that the clocks of the sheriff's and this deputy's "
                      "hosts agree (NTP/chrony).",
                  id);
  if (-age_s > options_.window_s)
    return refuse(std::move(v), OrdersRefusal::FromFuture,
                  "refusing orders from " + from + ": they are dated " + seconds(-age_s) +
                      " s ahead of this deputy's clock (limit " + seconds(options_.window_s) +
                      " s). Check that the clocks of the sheriff's and this deputy's hosts agree (NTP/chrony).",
                  id);
  if (const auto it = last_.find(in.sender); it != last_.end() && in.counter <= it->second)
    return refuse(std::move(v), OrdersRefusal::Replayed,
                  "refusing orders from " + from + ": counter " + std::to_string(in.counter) +
                      " is not above the last accepted " + std::to_string(it->second) + " (a replay)",
                  id);
  // One sheriff at a time: the pinned one, or the first heard until it falls silent or leaves.
  const bool unfollowed_goodbye = follow_ == 0 && in.leaving;  // obeyed, but not followed
  if (unfollowed_goodbye) {
  } else if (follow_ == 0) {
    follow_ = in.sender;
    v.notice = "following " + from + " (key " + fingerprint_ + ")";
  } else if (in.sender != follow_) {
    const double silent_s = (now_ms - follow_heard_ms_) * 1e-3;
    const bool may_take_over = options_.follow_sheriff == 0 && options_.handover_s > 0 &&
                               (follow_heard_ms_ == 0 || silent_s >= options_.handover_s);
    if (!may_take_over) {
      const bool new_rival = rival_ != in.sender || conflict(now_ms).empty();
      rival_ = in.sender;
      rival_name_ = in.orders.sheriff_name;
      rival_heard_ms_ = now_ms;
      GateVerdict out = refuse(std::move(v), OrdersRefusal::OtherSheriff,
                               "refusing orders from " + from + ": this deputy follows " +
                                   who(follow_, follow_name_) +
                                   (options_.follow_sheriff ? " (--sheriff-id)" : " (the first heard)"),
                               id);
      if (new_rival) out.notice = conflict(now_ms) + ": stop one of them, or run it with --observe";
      return out;
    }
    v.notice = "taking orders from " + from + ": " + who(follow_, follow_name_) +
               (follow_heard_ms_ == 0 ? " was never heard" : " has been silent for " + seconds(silent_s) + " s");
    follow_ = in.sender;
  } else if (follow_heard_ms_ == 0) {
    v.notice = "following " + from + " (--sheriff-id, key " + fingerprint_ + ")";
  }
  if (!unfollowed_goodbye) {
    follow_name_ = in.orders.sheriff_name;
    follow_heard_ms_ = now_ms == 0 ? 1 : now_ms;
  }
  // Written before the orders are obeyed: a replay after a restart finds the counter.
  last_[in.sender] = in.counter;
  while (last_.size() > options_.max_senders) {
    auto lowest = std::min_element(last_.begin(), last_.end(),
                                   [](const auto& a, const auto& b) { return a.second < b.second; });
    last_.erase(lowest);
  }
  std::string error;
  if (!save_state(&error)) {
    // Not fatal (a full disk must not keep the operator from stopping a command): the time
    // window still bounds a replay; counted and said.
    ++state_write_errors_;
    v.notice += (v.notice.empty() ? "" : "; ") + error;
  }
  ++accepted_;
  if (in.leaving && options_.follow_sheriff == 0 && follow_ == in.sender) {
    // Its last orders: obeyed, and the next keyed sheriff is followed as soon as it is heard.
    v.notice += (v.notice.empty() ? "" : "; ") + who(follow_, follow_name_) +
                " left (its last orders are applied); the next sheriff heard will be followed";
    follow_ = 0;
    rival_heard_ms_ = -1;
  }
  v.orders = std::move(in.orders);
  return v;
}

std::string OrdersGate::conflict(int64_t now_ms) const {
  if (rival_heard_ms_ < 0 || (now_ms - rival_heard_ms_) * 1e-3 > options_.conflict_hold_s) return "";
  return "two sheriffs: following " + who(follow_, follow_name_) + ", refusing " + who(rival_, rival_name_);
}

void OrdersGate::load_state() {
  const std::string& path = options_.state_path;
  if (path.empty()) return;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // first run: nothing accepted yet
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(path + ": deputy state file must be a regular file");
  if (st.st_mode & (S_IWGRP | S_IWOTH))
    throw std::runtime_error(path + ": deputy state file is writable by others; chmod 600 " + path);
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot read the deputy state file");
  std::string line;
  int n = 0;
  bool header = false;
  while (std::getline(f, line)) {
    ++n;
    if (line == kStateHeader) {
      header = true;
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    uint64_t sender = 0, counter = 0;
    std::string rest;
    if (!header || !(ss >> sender >> counter) || (ss >> rest) || sender == 0 ||
        sender > std::numeric_limits<uint32_t>::max())
      throw std::runtime_error(path + ":" + std::to_string(n) +
                               ": expected '<sender id> <counter>' after the line '" + kStateHeader +
                               "' (a corrupt deputy state file: remove it only if no recorded orders can be replayed)");
    auto& c = last_[static_cast<uint32_t>(sender)];
    c = std::max(c, counter);
  }
  if (!header && n > 0) throw std::runtime_error(path + ": not a deputy state file (no '" + kStateHeader + "' line)");
}

bool OrdersGate::save_state(std::string* error) {
  if (options_.state_path.empty()) return true;
  std::string text = std::string(kStateHeader) + "\n# deputy '" + host_ + "', key " + fingerprint_ +
                     "; per sheriff id the last counter accepted\n";
  for (const auto& [sender, counter] : last_) text += std::to_string(sender) + " " + std::to_string(counter) + "\n";
  try {
    util::write_key_file(options_.state_path, std::vector<uint8_t>(text.begin(), text.end()), /*overwrite=*/true,
                            "deputy state file");
    return true;
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return false;
  }
}

}  // namespace aerie::procman
