// The operator's signature on commands (common/seal/operator.hpp): a signed command verifies
// once for its session and its channel, and nothing else does -- no signature, another
// operator, a changed byte, another channel, another session, a replay, a counter left of the
// window; the key files round-trip with their modes enforced.
#include <gtest/gtest.h>
#include <sys/stat.h>


#include "common/seal/operator.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
using seal::CommandRefusal;

namespace {

template <typename F>
std::string thrown(F&& f) {
  return aerie::test::refusal([&](const std::string&) { f(); }, "");
}

std::vector<uint8_t> abort_cmd() { return {0x10, 0x20, 0x30, 0x40, 0x50}; }

struct Operator {
  seal::Session session = seal::new_session();
  seal::CommandSigner signer{seal::OperatorKey::generate()};
  seal::CommandVerifier verifier{{signer.public_key()}, session};
  std::span<const uint8_t> payload;
  std::string why;
  CommandRefusal verify(const std::string& channel, const std::vector<uint8_t>& env) {
    return verifier.verify(channel, env, payload, why);
  }
};

}  // namespace

TEST(OperatorSignature, ASignedCommandVerifiesOnceWithItsPayload) {
  Operator op;
  const auto env = op.signer.sign(op.session, "PILOT_CMD", abort_cmd());
  ASSERT_EQ(env.size(), abort_cmd().size() + seal::kCommandOverhead);
  EXPECT_EQ(op.verify("PILOT_CMD", env), CommandRefusal::None) << op.why;
  EXPECT_EQ(std::vector<uint8_t>(op.payload.begin(), op.payload.end()), abort_cmd());
  EXPECT_EQ(op.verify("PILOT_CMD", env), CommandRefusal::Replayed);
  EXPECT_NE(op.why.find("accepted already"), std::string::npos) << op.why;
  // The next one of the same operator verifies.
  EXPECT_EQ(op.verify("PILOT_CMD", op.signer.sign(op.session, "PILOT_CMD", abort_cmd())), CommandRefusal::None);
}

TEST(OperatorSignature, EverythingButTheOperatorsOwnCommandIsRefusedByReason) {
  Operator op;
  const auto env = op.signer.sign(op.session, "PILOT_CMD", abort_cmd());
  // A bare command (an intruder holding the mission key only).
  EXPECT_EQ(op.verify("PILOT_CMD", abort_cmd()), CommandRefusal::Unsigned);
  EXPECT_NE(op.why.find("carries no operator signature"), std::string::npos) << op.why;
  // Another operator's key (not on this vehicle's list).
  seal::CommandSigner stranger(seal::OperatorKey::generate());
  EXPECT_EQ(op.verify("PILOT_CMD", stranger.sign(op.session, "PILOT_CMD", abort_cmd())), CommandRefusal::BadSignature);
  // One byte changed anywhere after the session: payload, counter, signature.
  for (const size_t at : {env.size() - 1, seal::kSessionSize + 2, seal::kSessionSize + 8 + 5}) {
    auto t = env;
    t[at] ^= 0x01;
    EXPECT_EQ(op.verify("PILOT_CMD", t), CommandRefusal::BadSignature) << "byte " << at;
  }
  // The same command moved to another channel.
  EXPECT_EQ(op.verify("TRACK_CMD", env), CommandRefusal::BadSignature);
  // Signed for another session (recorded before the air half restarted).
  const auto old = op.signer.sign(seal::new_session(), "PILOT_CMD", abort_cmd());
  EXPECT_EQ(op.verify("PILOT_CMD", old), CommandRefusal::OtherSession);
  // None of the refusals moved the window: the genuine command still verifies, once.
  EXPECT_EQ(op.verify("PILOT_CMD", env), CommandRefusal::None) << op.why;
}

TEST(OperatorSignature, ReorderedCommandsInsideTheWindowPassOnceAndOlderOnesAreRefused) {
  Operator op;
  const uint64_t top = 20000;
  const auto at = [&](uint64_t c) { return op.signer.sign_with_counter(op.session, c, "TRACK_CMD", abort_cmd()); };
  EXPECT_EQ(op.verify("TRACK_CMD", at(top)), CommandRefusal::None);
  EXPECT_EQ(op.verify("TRACK_CMD", at(top - 5)), CommandRefusal::None);  // late, inside the window
  EXPECT_EQ(op.verify("TRACK_CMD", at(top - 5)), CommandRefusal::Replayed);
  EXPECT_EQ(op.verify("TRACK_CMD", at(top - seal::ReplayWindow::kWindowSize - 1)), CommandRefusal::TooOld);
}

TEST(OperatorSignature, SeveralOperatorsEachWithTheirOwnCounters) {
  const seal::Session session = seal::new_session();
  seal::CommandSigner a(seal::OperatorKey::generate()), b(seal::OperatorKey::generate());
  seal::CommandVerifier v({a.public_key(), b.public_key()}, session);
  std::span<const uint8_t> payload;
  std::string why;
  EXPECT_EQ(v.verify("PILOT_CMD", a.sign(session, "PILOT_CMD", abort_cmd()), payload, why), CommandRefusal::None);
  // b's counter 1 is not a's counter 1.
  EXPECT_EQ(v.verify("PILOT_CMD", b.sign(session, "PILOT_CMD", abort_cmd()), payload, why), CommandRefusal::None);
  EXPECT_THROW(seal::CommandVerifier({}, session), std::invalid_argument);
}

TEST(OperatorKeyFiles, RoundTripWithTheirModes) {
  const std::string secret = (aerie::test::scratch_dir("keys") / "operator.key").string(), pub = secret + ".pub";
  const seal::OperatorKey key = seal::OperatorKey::generate();
  key.save(secret);
  key.public_key().save(pub);
  struct stat st{};
  ASSERT_EQ(::stat(secret.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(::stat(pub.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
  const seal::OperatorKey back = seal::OperatorKey::load(secret);
  EXPECT_EQ(back.public_key().bytes, key.public_key().bytes);
  EXPECT_EQ(seal::OperatorPublicKey::load(pub).bytes, key.public_key().bytes);
  EXPECT_EQ(key.public_key().fingerprint().size(), 19u);  // "xxxx:xxxx:xxxx:xxxx"
  // A signature from the reloaded key verifies under the saved public key.
  const seal::Session s = seal::new_session();
  seal::CommandSigner signer(back.clone());
  seal::CommandVerifier v({seal::OperatorPublicKey::load(pub)}, s);
  std::span<const uint8_t> payload;
  std::string why;
  EXPECT_EQ(v.verify("MAP_CMD", signer.sign(s, "MAP_CMD", abort_cmd()), payload, why), CommandRefusal::None);

  // Modes: a secret others can read, a public key others can write: refused, naming the fix.
  ::chmod(secret.c_str(), 0640);
  EXPECT_NE(thrown([&] { seal::OperatorKey::load(secret); }).find("chmod 600"), std::string::npos);
  ::chmod(pub.c_str(), 0666);
  EXPECT_NE(thrown([&] { seal::OperatorPublicKey::load(pub); }).find("writable by others"), std::string::npos);
  // Existing files are not replaced unless asked.
  ::chmod(secret.c_str(), 0600);
  EXPECT_NE(thrown([&] { key.save(secret); }).find("exists already"), std::string::npos);
}
