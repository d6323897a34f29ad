#pragma once
// aerie-mavlink --check (issue 45 §5, docs/mavlink.md "Bring-up on a real vehicle"): is this
// autopilot set up for Aerie? Without I/O of its own, as AutopilotLink: bytes from the autopilot
// go in (receive), poll(now) says what to write, every time is passed in (the wall clock live,
// simulation time in tests).
//
// What it does on the wire:
//  * HEARTBEAT at 1 Hz as MAV_TYPE_ONBOARD_CONTROLLER, and waits for the autopilot's (the first
//    heard that is an autopilot, or the configured system id); none within heartbeat_timeout_s:
//    one FAIL and done.
//  * The version: COMMAND_LONG MAV_CMD_REQUEST_MESSAGE (512) for AUTOPILOT_VERSION (148), sent
//    again with confirmation + 1 after retry_s, `attempts` times; an autopilot that answers
//    UNSUPPORTED is asked with MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES (520), as older firmware
//    wants. flight_sw_version is shown as major.minor.patch (its bytes 3, 2, 1; byte 0 the
//    FIRMWARE_VERSION_TYPE).
//  * The parameters that matter for this autopilot and this configuration (the docs' table):
//    PARAM_REQUEST_READ by name (param_index -1), at most `window` unanswered at once, each sent
//    again after retry_s, `attempts` times; one that never answers is "not found on this
//    autopilot" (both firmwares stay silent for a name they have not). PARAM_VALUE's integers
//    are read as the autopilot encodes them: bytewise (PX4, MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE)
//    or C cast (ArduPilot, ..._PARAM_ENCODE_C_CAST).
//  * Signing, as AutopilotLink::enable_signing: what it sends is signed, and the autopilot's
//    frames must carry a valid signature (but HEARTBEAT and RADIO_STATUS).
// The whole check gives up after timeout_s: whatever is unanswered then FAILs.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "air/mavlink/autopilot_link.hpp"
#include "common/mavlink/frame.hpp"
#include "common/mavlink/modes.hpp"
#include "common/mavlink/parser.hpp"
#include "common/mavlink/signing.hpp"

namespace aerie::bridge {

enum class Verdict { Pass, Warn, Fail };
const char* to_string(Verdict v);  // "PASS", "WARN", "FAIL"

struct CheckItem {
  std::string name;      // a parameter's name, or "heartbeat", "version", "signing"
  Verdict verdict = Verdict::Pass;
  std::string found;     // what was found: "0 (offboard loss never detected)", "not found on this autopilot"
  std::string fix;       // what to do ("set COM_OF_LOSS_T 1.0"); empty when nothing is to be done
  bool has_value = true; // found is a value (the line says "NAME = found"), else a sentence ("NAME: found")
};
// "FAIL COM_OF_LOSS_T = 0 (offboard loss never detected) — set COM_OF_LOSS_T 1.0"
std::string to_line(const CheckItem& item);

struct PreflightConfig {
  int system_id = 1;            // Aerie's, as BridgeConfig
  int component_id = 191;
  int autopilot_system_id = 0;  // 0: the first autopilot heard
  bool send_odometry = true;    // the bridge sends ODOMETRY: the estimator must fuse it
  LandingPath landing_path = LandingPath::Aerie;  // Autopilot: its precision landing must be there
  double heartbeat_timeout_s = 5.0;  // no autopilot heartbeat this long: FAIL, done
  double retry_s = 1.0;              // per attempt of a request
  int attempts = 3;                  // sends of each request before it counts as unanswered
  int window = 5;                    // parameter requests unanswered at once (ArduPilot queues few)
  double timeout_s = 60.0;           // the whole check
  void validate() const;             // std::invalid_argument naming the field
  static PreflightConfig from(const BridgeConfig& b);
};

class PreflightCheck {
 public:
  explicit PreflightCheck(PreflightConfig cfg);

  // Signs what is sent and refuses unsigned frames from the autopilot (but HEARTBEAT and
  // RADIO_STATUS); persisted_timestamp: the last one saved (0 = none).
  void enable_signing(const mavlink::Key& key, uint8_t link_id, uint64_t persisted_timestamp);
  bool signing() const { return signer_.has_value(); }

  void receive(std::span<const uint8_t> bytes, int64_t now_us);
  // The frames to write to the autopilot now; the check advances here (retries, time-outs).
  std::vector<std::vector<uint8_t>> poll(int64_t now_us);

  bool done() const { return done_; }
  // One item per check, in the order printed; complete once done().
  const std::vector<CheckItem>& items() const { return items_; }
  // Done and no item FAILs.
  bool passed() const;

  // The autopilot heard (Other until its heartbeat).
  mavlink::Autopilot autopilot() const { return autopilot_; }
  // The parameters asked for, in order (after the heartbeat; tests).
  std::vector<std::string> parameters_asked() const;
  int64_t frames_out() const { return frames_out_; }
  const mavlink::ParserCounters& parser_counters() const { return parser_.counters(); }
  std::optional<uint64_t> last_signing_timestamp() const {
    return signer_ ? std::optional<uint64_t>(signer_->last_timestamp()) : std::nullopt;
  }

 private:
  struct ParamRequest {
    std::string name;
    int sent = 0;              // attempts so far
    int64_t sent_at_us = 0;
    std::optional<mavlink::ParamValue> answer;
    bool gave_up = false;
  };
  void on_frame(const mavlink::Frame& f, int64_t now_us);
  void start(int64_t now_us);  // the autopilot is heard: plan the requests
  void send_version_request(int64_t now_us);
  void finish(int64_t now_us);
  std::optional<double> value_of(const std::string& name) const;
  template <class Msg>
  void emit(const Msg& msg);

  PreflightConfig cfg_;
  mavlink::Parser parser_;
  std::optional<mavlink::Signer> signer_;
  std::string key_fingerprint_;
  std::shared_ptr<int64_t> now_us_ = std::make_shared<int64_t>(0);
  uint8_t seq_ = 0;
  int64_t frames_out_ = 0;
  std::vector<std::vector<uint8_t>> out_;
  int64_t started_us_ = -1;        // the first poll or receive
  int64_t last_heartbeat_sent_ = 0;
  bool heartbeat_sent_ = false;

  // The autopilot.
  bool heard_ = false;
  mavlink::Autopilot autopilot_ = mavlink::Autopilot::Other;
  mavlink::Heartbeat heartbeat_{};
  uint8_t ap_sysid_ = 0, ap_compid_ = 0;
  bool signed_frame_seen_ = false;  // a signed frame from the autopilot was accepted

  // The version request.
  uint16_t version_command_ = mavlink::mav_cmd::kRequestMessage;
  int version_sent_ = 0;
  int64_t version_sent_at_us_ = 0;
  std::optional<mavlink::AutopilotVersion> version_;
  std::optional<uint8_t> version_refused_;  // the ACK's result when it was not ACCEPTED
  bool version_done_ = false;

  std::vector<ParamRequest> params_;
  bool done_ = false;
  std::vector<CheckItem> items_;
};

}  // namespace aerie::bridge
