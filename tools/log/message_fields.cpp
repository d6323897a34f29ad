#include "tools/log/message_fields.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "common/bus/wire.hpp"
#include "tools/log/type_registry.hpp"

namespace aerie::logtools {
namespace {

using bus::wire::Field;
using bus::wire::Kind;
using bus::wire::Type;

const Type* catalogue_type(int64_t fingerprint) {
  for (const bus::wire::Entry& e : bus::wire::catalogue())
    if (e.hash() == fingerprint) return e.type;
  return nullptr;
}

bool is_integer(Kind k) { return k == Kind::Int8 || k == Kind::Int16 || k == Kind::Int32 || k == Kind::Int64; }

// A payload already checked by bus::wire_error(), read front to back (big-endian, as LCM encodes).
class Cursor {
 public:
  Cursor(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}

  const uint8_t* take(size_t n) {
    if (n > static_cast<size_t>(end_ - p_)) throw std::logic_error("message_fields: read past a checked payload");
    const uint8_t* at = p_;
    p_ += n;
    return at;
  }
  uint64_t bits(size_t bytes) {
    const uint8_t* b = take(bytes);
    uint64_t v = 0;
    for (size_t i = 0; i < bytes; ++i) v = (v << 8) | b[i];
    return v;
  }
  int64_t integer(size_t bytes) {  // sign-extended
    const uint64_t v = bits(bytes);
    const unsigned shift = 64 - 8 * static_cast<unsigned>(bytes);
    return static_cast<int64_t>(v << shift) >> shift;
  }
  std::string_view string() {  // int32 length with the NUL, the bytes, the NUL
    const auto len = static_cast<size_t>(integer(4));
    return {reinterpret_cast<const char*>(take(len)), len > 0 ? len - 1 : 0};
  }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
};

struct Value {
  bool integer;
  int64_t i;
  double d;
};

Value read_value(Kind k, Cursor& c) {
  switch (k) {
    case Kind::Int8: return {true, c.integer(1), 0};
    case Kind::Int16: return {true, c.integer(2), 0};
    case Kind::Int32: return {true, c.integer(4), 0};
    case Kind::Int64: return {true, c.integer(8), 0};
    case Kind::Byte: return {true, static_cast<int64_t>(c.bits(1)), 0};
    case Kind::Boolean: return {true, c.bits(1) != 0 ? 1 : 0, 0};
    case Kind::Float: return {false, 0, std::bit_cast<float>(static_cast<uint32_t>(c.bits(4)))};
    case Kind::Double: return {false, 0, std::bit_cast<double>(c.bits(8))};
    default: throw std::logic_error("message_fields: not a number");
  }
}

double abs_difference(const Value& a, const Value& b) {
  if (a.integer)  // exact in 64 bits, whatever the signs
    return static_cast<double>(a.i >= b.i ? static_cast<uint64_t>(a.i) - static_cast<uint64_t>(b.i)
                                          : static_cast<uint64_t>(b.i) - static_cast<uint64_t>(a.i));
  if (std::isnan(a.d) || std::isnan(b.d))
    return std::isnan(a.d) && std::isnan(b.d) ? 0 : std::numeric_limits<double>::infinity();
  return a.d == b.d ? 0 : std::fabs(a.d - b.d);  // equal infinities differ by nothing
}

using Ints = std::array<int64_t, bus::wire::kMaxFields>;  // scalar integer fields so far (array sizes)

std::vector<int64_t> dims_of(const Field& f, const Ints& ints) {
  std::vector<int64_t> dims;
  for (const bus::wire::Dim& d : f.dims) dims.push_back(d.field < 0 ? d.size : ints[static_cast<size_t>(d.field)]);
  return dims;
}

uint64_t elements(const std::vector<int64_t>& dims) {
  uint64_t n = 1;
  for (const int64_t d : dims) n *= static_cast<uint64_t>(d);
  return n;
}

std::string shape_of(const std::vector<int64_t>& dims) {  // "3", "4x2"
  std::string s;
  for (const int64_t d : dims) s += (s.empty() ? "" : "x") + std::to_string(d);
  return s;
}

// Walks two messages of one type side by side. Arrays whose sizes differ are skipped on both
// sides (their values cannot be paired) and reported as the shape difference.
class Comparer {
 public:
  Comparer(Cursor a, Cursor b, FieldDifference& out) : a_(a), b_(b), out_(out) {}

  void compare(const Type& t) {
    Ints ia{}, ib{};
    for (size_t i = 0; i < t.fields.size(); ++i) {
      const Field& f = t.fields[i];
      const std::vector<int64_t> dims = dims_of(f, ia), dims_b = dims_of(f, ib);
      path_.push_back({&f, dims, 0});
      if (dims != dims_b) {
        if (out_.shape.empty())
          out_.shape = render(false) + ": " + shape_of(dims) + " vs " + shape_of(dims_b) + " elements";
        skip(f, elements(dims), a_);
        skip(f, elements(dims_b), b_);
        path_.pop_back();
        continue;
      }
      const uint64_t n = elements(dims);
      for (uint64_t k = 0; k < n; ++k) {
        path_.back().index = k;
        if (f.kind == Kind::Struct) {
          compare(*f.type);
        } else if (f.kind == Kind::String) {
          if (a_.string() != b_.string() && out_.text.empty()) out_.text = render();
        } else {
          const Value va = read_value(f.kind, a_), vb = read_value(f.kind, b_);
          if (dims.empty() && is_integer(f.kind)) {
            ia[i] = va.i;
            ib[i] = vb.i;
          }
          if (const double d = abs_difference(va, vb); d > out_.max_abs) {
            out_.max_abs = d;
            out_.field = render();
          }
        }
      }
      path_.pop_back();
    }
  }

 private:
  struct Step {
    const Field* field;
    std::vector<int64_t> dims;  // empty: a scalar
    uint64_t index;             // row-major element index
  };

  static void skip(const Field& f, uint64_t n, Cursor& c) {
    for (uint64_t k = 0; k < n; ++k) {
      if (f.kind == Kind::Struct) {
        skip_struct(*f.type, c);
      } else if (f.kind == Kind::String) {
        c.string();
      } else {
        c.take(bus::wire::primitive_bytes(f.kind));
      }
    }
  }

  static void skip_struct(const Type& t, Cursor& c) {
    Ints ints{};
    for (size_t i = 0; i < t.fields.size(); ++i) {
      const Field& f = t.fields[i];
      if (f.dims.empty() && is_integer(f.kind)) {
        ints[i] = read_value(f.kind, c).i;
      } else {
        skip(f, elements(dims_of(f, ints)), c);
      }
    }
  }

  // "levels[1].u[3]"; without the last index: "levels[1].u".
  std::string render(bool last_index = true) const {
    std::string s;
    for (const Step& st : path_) {
      if (!s.empty()) s += '.';
      s += st.field->name;
      if (!last_index && &st == &path_.back()) break;
      std::string index;
      uint64_t k = st.index;
      for (size_t d = st.dims.size(); d-- > 0;) {
        const auto size = static_cast<uint64_t>(st.dims[d]);
        index.insert(0, "[" + std::to_string(size ? k % size : 0) + "]");
        if (size) k /= size;
      }
      s += index;
    }
    return s;
  }

  Cursor a_, b_;
  FieldDifference& out_;
  std::vector<Step> path_;
};

}  // namespace

FieldDifference compare_fields(const uint8_t* a, size_t a_size, const uint8_t* b, size_t b_size) {
  FieldDifference out;
  const int64_t fp = fingerprint_of(a, a_size);
  const Type* type = catalogue_type(fp);
  if (!type || fingerprint_of(b, b_size) != fp || bus::wire_error(fp, a, a_size) || bus::wire_error(fp, b, b_size))
    return out;
  out.comparable = true;
  out.type = type->name;
  Comparer(Cursor(a + 8, a_size - 8), Cursor(b + 8, b_size - 8), out).compare(*type);
  return out;
}

}  // namespace aerie::logtools
