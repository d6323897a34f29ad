#include "common/bus/wire.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <limits>

namespace aerie::bus {
namespace {

using wire::Field;
using wire::Kind;
using wire::primitive_bytes;
using wire::Type;

constexpr int kMaxDepth = 32;  // nested structs; the catalogue has 3 levels

bool is_integer(Kind k) { return k == Kind::Int8 || k == Kind::Int16 || k == Kind::Int32 || k == Kind::Int64; }

// Smallest encoding of one element of the field (at least 1, so that a count is bounded by the bytes).
size_t element_min_bytes(const Field& f) {
  if (f.kind == Kind::Struct) return std::max<size_t>(1, static_cast<size_t>(f.type->min_bytes));
  return f.kind == Kind::String ? 5 : primitive_bytes(f.kind);
}

// Where the walk is: a field of a struct (element `index` of it when an array), inside `up`.
struct Where {
  const Where* up;
  const Type* type;
  const Field* field;
  int64_t index;  // -1: scalar
};

std::string step(const Where& w) {
  return std::string(w.field->name) + (w.index >= 0 ? "[" + std::to_string(w.index) + "]" : "");
}

std::string path(const Where& w) {  // aerie.stereo_image_t.left.metadata[0]
  return (w.up ? path(*w.up) : std::string(w.type->name)) + "." + step(w);
}

struct Refused {
  std::string reason;
};

class Walker {
 public:
  Walker(const uint8_t* data, size_t size) : p_(data), left_(size) {}
  size_t left() const { return left_; }

  void walk(const Type& t, const Where* up, int depth) {
    if (depth > kMaxDepth) refuse(*up, "structs nested deeper than " + std::to_string(kMaxDepth));
    std::array<int64_t, wire::kMaxFields> ints;  // scalar integer fields so far (dims refer to earlier ones)
    for (size_t i = 0; i < t.fields.size(); ++i) {
      const Field& f = t.fields[i];
      Where w{up, &t, &f, -1};
      const uint64_t n = elements(t, w, ints);
      if (f.kind == Kind::String || f.kind == Kind::Struct) {
        for (uint64_t k = 0; k < n; ++k) {
          w.index = f.dims.empty() ? -1 : static_cast<int64_t>(k);
          if (f.kind == Kind::String) string(w);
          else walk(*f.type, &w, depth + 1);
        }
      } else if (f.dims.empty() && is_integer(f.kind)) {
        ints[i] = integer(w, primitive_bytes(f.kind));
      } else {
        take(w, n * primitive_bytes(f.kind));
      }
    }
  }

 private:
  [[noreturn]] void refuse(const Where& w, const std::string& what) const {
    std::string reason = std::string(w.type->name) + "." + step(w) + ": " + what;
    if (w.up) reason += " (in " + path(*w.up) + ")";
    throw Refused{reason};
  }

  const uint8_t* take(const Where& w, size_t bytes) {
    if (bytes > left_)
      refuse(w, "needs " + std::to_string(bytes) + " bytes, " + std::to_string(left_) + " remain (truncated)");
    const uint8_t* at = p_;
    p_ += bytes;
    left_ -= bytes;
    return at;
  }

  int64_t integer(const Where& w, size_t bytes) {  // big-endian, sign-extended
    const uint8_t* b = take(w, bytes);
    uint64_t v = b[0] & 0x80 ? ~uint64_t{0} : 0;
    for (size_t i = 0; i < bytes; ++i) v = (v << 8) | b[i];
    return static_cast<int64_t>(v);
  }

  // Number of elements of field w (1 for a scalar): every variable dimension checked against
  // sign and cap, and the whole array against the bytes left, so that no product overflows.
  uint64_t elements(const Type& t, const Where& w, const std::array<int64_t, wire::kMaxFields>& ints) const {
    const auto& dims = w.field->dims;
    uint64_t n = 1;
    std::string what;
    for (const wire::Dim& d : dims) {
      const int64_t size = d.field < 0 ? d.size : ints[static_cast<size_t>(d.field)];
      if (d.field >= 0) {
        const Field& count = t.fields[static_cast<size_t>(d.field)];
        what = "count " + std::string(count.name) + " = " + std::to_string(size);
        if (size < 0) refuse(w, what + " is negative");
        if (size > count.cap) refuse(w, what + " exceeds the cap " + std::to_string(count.cap));
      }
      n = size == 0 ? 0 : std::min<uint64_t>(n, left_ + 1) * static_cast<uint64_t>(std::min<int64_t>(size, 1LL << 32));
    }
    const size_t min_bytes = element_min_bytes(*w.field);
    if (!dims.empty() && n > left_ / min_bytes) {
      if (dims.size() > 1 || what.empty()) what = std::to_string(n) + " elements";
      refuse(w, what + " of at least " + std::to_string(min_bytes) + " bytes cannot fit in the " +
                    std::to_string(left_) + " bytes left");
    }
    return n;
  }

  void string(const Where& w) {
    const int64_t len = integer(w, 4);  // includes the NUL
    const std::string what = "string length " + std::to_string(len);
    if (len < 0) refuse(w, what + " is negative");
    if (len == 0) refuse(w, what + " lacks the NUL terminator it counts");
    if (len - 1 > w.field->cap) refuse(w, what + " exceeds the cap " + std::to_string(w.field->cap));
    if (static_cast<uint64_t>(len) > left_) refuse(w, what + " exceeds the " + std::to_string(left_) + " bytes left");
    const uint8_t* text = take(w, static_cast<size_t>(len));
    if (text[len - 1] != 0) refuse(w, what + " does not end with NUL");
    // lcm-gen encodes strlen() bytes but sizes the message by std::string::size(): a decoded NUL
    // inside would make any re-encoding (aerie-link's JPEG re-encoding keeps image metadata)
    // shorter than its size, padded with bytes every receiver refuses (uninitialised ones through
    // lcm::LCM::publish(channel, &msg)).
    if (std::memchr(text, 0, static_cast<size_t>(len - 1))) refuse(w, what + " holds a NUL before its end");
  }

  const uint8_t* p_;
  size_t left_;
};

std::string hex(int64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

std::optional<std::string> wire_error(int64_t type_hash, const void* data, size_t size) {
  const Type* type = nullptr;
  for (const wire::Entry& e : wire::catalogue())
    if (e.hash() == type_hash) type = e.type;
  if (!type) throw std::logic_error("wire_error: no type of lcmtypes/ has the fingerprint " + hex(type_hash));
  const std::string name = type->name;
  const auto* bytes = static_cast<const uint8_t*>(data);
  if (size > static_cast<size_t>(std::numeric_limits<int32_t>::max()))
    return name + ": " + std::to_string(size) + " bytes, more than an LCM decoder takes";
  if (size < 8) return name + ": " + std::to_string(size) + " bytes, shorter than the 8-byte fingerprint";
  int64_t fingerprint = 0;
  for (int i = 0; i < 8; ++i) fingerprint = static_cast<int64_t>(static_cast<uint64_t>(fingerprint) << 8 | bytes[i]);
  if (fingerprint != type_hash)
    return name + ": fingerprint " + hex(fingerprint) + " is not the type's " + hex(type_hash) + " (another type?)";
  try {
    Walker walker(bytes + 8, size - 8);
    walker.walk(*type, nullptr, 0);
    if (walker.left() > 0) return name + ": " + std::to_string(walker.left()) + " bytes after the end of the message";
  } catch (const Refused& r) {
    return r.reason;
  }
  return std::nullopt;
}

}  // namespace aerie::bus
