#pragma once
// Bounded decoding of LCM messages (docs/messages.md "Bounded decoding").
// Debian's lcm-gen 1.3.1 decoders trust length prefixes: a negative string length, an array
// count whose byte size overflows their bound check, or a huge count crashes or stalls the
// process before decode() can fail. Every decode of bytes from outside (bus, logs, relays)
// therefore goes through decode_bounded(), which first walks the payload along the type's
// wire schema (generated from lcmtypes/*.lcm by lcmtypes/gen_wire_schema.py) and refuses any
// length or count that is negative, that the rest of the payload cannot hold, or that exceeds
// its cap in lcmtypes/decode_limits.txt, naming the type, the field and the value.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

namespace aerie::bus {

namespace wire {

enum class Kind : uint8_t { Int8, Int16, Int32, Int64, Float, Double, Boolean, Byte, String, Struct };

struct Type;

constexpr size_t primitive_bytes(Kind k) {  // 0 for String and Struct
  switch (k) {
    case Kind::Int8: case Kind::Boolean: case Kind::Byte: return 1;
    case Kind::Int16: return 2;
    case Kind::Int32: case Kind::Float: return 4;
    case Kind::Int64: case Kind::Double: return 8;
    default: return 0;
  }
}

// One array dimension: the constant `size`, or (field >= 0) the value of that earlier integer field.
struct Dim {
  int64_t size;
  int field;
};

struct Field {
  const char* name;
  Kind kind;
  const Type* type;          // Kind::Struct
  std::span<const Dim> dims;  // empty: a scalar
  int64_t cap;               // count field: most elements; string: most bytes (NUL excluded)
};

struct Type {
  const char* name;  // "aerie.image_t"
  std::span<const Field> fields;
  int64_t min_bytes;  // smallest encoding without the fingerprint
};

// A top-level type of the catalogue and its lcm-gen fingerprint.
struct Entry {
  const Type* type;
  int64_t (*hash)();
};

inline constexpr int64_t kNoCap = std::numeric_limits<int64_t>::max();
inline constexpr size_t kMaxFields = 64;  // per struct; the generator asserts it

// Every type of lcmtypes/, generated at build time.
std::span<const Entry> catalogue();

}  // namespace wire

// Why `data` is not a well-formed encoding of the catalogue type with this fingerprint
// (e.g. "aerie.track_cmd_t.tracker: string length -2147483648 is negative"), or nullopt.
// Trailing bytes after the message are refused too. Never reads outside [data, data + size).
std::optional<std::string> wire_error(int64_t type_hash, const void* data, size_t size);

// Decodes bytes from outside into `out` only once wire_error() found nothing; false with the
// reason in *why otherwise.
template <typename Msg>
bool decode_bounded(const void* data, size_t size, Msg& out, std::string* why = nullptr) {
  std::optional<std::string> error = wire_error(Msg::getHash(), data, size);
  if (!error && out.decode(data, 0, static_cast<int>(size)) < 0)
    error = std::string(Msg::getTypeName()) + ": lcm-gen decoder refused a payload the wire check accepted";
  if (error && why) *why = std::move(*error);
  return !error;
}

// The same, throwing std::invalid_argument with the reason (a bus subscription counts it as malformed).
template <typename Msg>
Msg decode_bounded(const void* data, size_t size) {
  Msg msg{};
  std::string why;
  if (!decode_bounded(data, size, msg, &why)) throw std::invalid_argument(why);
  return msg;
}

}  // namespace aerie::bus
