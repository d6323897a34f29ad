#pragma once
// The catalogue's form (catalogue.hpp): a message is a struct with `kId`, `kName` and a
// `static constexpr auto fields()` that lists each field ONCE, in the order of the XML
// definition, as field("name", &Msg::member) or, after <extensions/>, extension(...).
// Everything the wire needs is derived from that list at compile time (MAVLink "Serialization"
// and "CRC_EXTRA" in the protocol documentation):
//   * wire order: non-extension fields stable-sorted by element size, largest first, then the
//     extension fields in XML order;
//   * min_length (non-extension fields) and max_length (all fields) of the payload;
//   * CRC_EXTRA: X.25 over "NAME " and, for each non-extension field in wire order,
//     "type name " and, for an array, its length as one byte; folded as (crc & 0xFF) ^ (crc >> 8).
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "common/mavlink/crc.hpp"

namespace aerie::mavlink {

// The XML type name of a field's element type (uint8_t_mavlink_version is written uint8_t).
template <class T>
struct WireType;
template <> struct WireType<uint8_t> { static constexpr std::string_view name = "uint8_t"; };
template <> struct WireType<int8_t> { static constexpr std::string_view name = "int8_t"; };
template <> struct WireType<char> { static constexpr std::string_view name = "char"; };
template <> struct WireType<uint16_t> { static constexpr std::string_view name = "uint16_t"; };
template <> struct WireType<int16_t> { static constexpr std::string_view name = "int16_t"; };
template <> struct WireType<uint32_t> { static constexpr std::string_view name = "uint32_t"; };
template <> struct WireType<int32_t> { static constexpr std::string_view name = "int32_t"; };
template <> struct WireType<uint64_t> { static constexpr std::string_view name = "uint64_t"; };
template <> struct WireType<int64_t> { static constexpr std::string_view name = "int64_t"; };
template <> struct WireType<float> { static constexpr std::string_view name = "float"; };
template <> struct WireType<double> { static constexpr std::string_view name = "double"; };

template <class T>
struct FieldShape {
  using Element = T;
  static constexpr size_t count = 1;
  static constexpr bool is_array = false;
};
template <class T, size_t N>
struct FieldShape<std::array<T, N>> {
  using Element = T;
  static constexpr size_t count = N;
  static constexpr bool is_array = true;
};

template <class M, class T>
struct Field {
  using Message = M;
  using Type = T;
  std::string_view name;
  T M::*member;
  bool is_extension;
};

template <class M, class T>
constexpr Field<M, T> field(std::string_view name, T M::*member) {
  return {name, member, false};
}
template <class M, class T>
constexpr Field<M, T> extension(std::string_view name, T M::*member) {
  return {name, member, true};
}

// One field as the derivations see it.
struct FieldInfo {
  std::string_view name;
  std::string_view type;  // element type as in the XML ("float", "char", ...)
  size_t element_size;
  size_t count;  // 1 for a scalar
  bool is_array;
  bool is_extension;
};

template <class M>
struct Layout {
  static constexpr auto kFieldList = M::fields();
  static constexpr size_t kCount = std::tuple_size_v<decltype(kFieldList)>;

  template <size_t I>
  static constexpr FieldInfo info() {
    constexpr auto f = std::get<I>(kFieldList);
    using T = typename decltype(f)::Type;
    using Shape = FieldShape<T>;
    return {f.name, WireType<typename Shape::Element>::name, sizeof(typename Shape::Element), Shape::count,
            Shape::is_array, f.is_extension};
  }
  template <size_t... I>
  static constexpr std::array<FieldInfo, kCount> infos(std::index_sequence<I...>) {
    return {info<I>()...};
  }
  // Fields in XML order.
  static constexpr std::array<FieldInfo, kCount> kFields = infos(std::make_index_sequence<kCount>{});

  // kOrder[k] = XML index of the field at wire position k (insertion sort: stable).
  static constexpr std::array<size_t, kCount> order() {
    std::array<size_t, kCount> order{};
    size_t n = 0;
    for (size_t i = 0; i < kCount; ++i) {
      if (kFields[i].is_extension) continue;
      size_t k = n++;
      while (k > 0 && kFields[order[k - 1]].element_size < kFields[i].element_size) {
        order[k] = order[k - 1];
        --k;
      }
      order[k] = i;
    }
    for (size_t i = 0; i < kCount; ++i)
      if (kFields[i].is_extension) order[n++] = i;
    return order;
  }
  static constexpr std::array<size_t, kCount> kOrder = order();

  // kOffsets[i] = byte offset in the payload of XML field i.
  static constexpr std::array<size_t, kCount> offsets() {
    std::array<size_t, kCount> offsets{};
    size_t at = 0;
    for (size_t k = 0; k < kCount; ++k) {
      offsets[kOrder[k]] = at;
      at += kFields[kOrder[k]].element_size * kFields[kOrder[k]].count;
    }
    return offsets;
  }
  static constexpr std::array<size_t, kCount> kOffsets = offsets();

  static constexpr size_t length(bool with_extensions) {
    size_t n = 0;
    for (const FieldInfo& f : kFields)
      if (with_extensions || !f.is_extension) n += f.element_size * f.count;
    return n;
  }
  static constexpr size_t kMinLength = length(false);
  static constexpr size_t kMaxLength = length(true);
  static_assert(kMaxLength <= 255, "a MAVLink payload holds at most 255 bytes");
  static_assert(kMinLength >= 1, "a MAVLink message has at least one non-extension field");

  static constexpr uint8_t crc_extra() {
    Crc16 crc;
    crc.add(M::kName);
    crc.add(std::string_view(" "));
    for (size_t k = 0; k < kCount; ++k) {
      const FieldInfo& f = kFields[kOrder[k]];
      if (f.is_extension) continue;
      crc.add(f.type);
      crc.add(std::string_view(" "));
      crc.add(f.name);
      crc.add(std::string_view(" "));
      if (f.is_array) crc.add(static_cast<uint8_t>(f.count));
    }
    return static_cast<uint8_t>((crc.value() & 0xFF) ^ (crc.value() >> 8));
  }
  static constexpr uint8_t kCrcExtra = crc_extra();
};

template <class M>
constexpr uint8_t crc_extra() {
  return Layout<M>::kCrcExtra;
}
template <class M>
constexpr size_t min_length() {
  return Layout<M>::kMinLength;
}
template <class M>
constexpr size_t max_length() {
  return Layout<M>::kMaxLength;
}

namespace detail {

template <class T>
void put_scalar(uint8_t* out, T value) {
  using U = std::conditional_t<sizeof(T) == 1, uint8_t,
            std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;
  U bits = std::bit_cast<U>(value);
  for (size_t i = 0; i < sizeof(T); ++i) out[i] = static_cast<uint8_t>(bits >> (8 * i));  // little-endian
}

template <class T>
T get_scalar(const uint8_t* in) {
  using U = std::conditional_t<sizeof(T) == 1, uint8_t,
            std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;
  U bits = 0;
  for (size_t i = 0; i < sizeof(T); ++i) bits = static_cast<U>(bits | (static_cast<U>(in[i]) << (8 * i)));
  return std::bit_cast<T>(bits);
}

template <class T>
void put(uint8_t* out, const T& value) {
  if constexpr (FieldShape<T>::is_array) {
    using E = typename FieldShape<T>::Element;
    for (size_t i = 0; i < value.size(); ++i) put_scalar<E>(out + i * sizeof(E), value[i]);
  } else {
    put_scalar<T>(out, value);
  }
}

template <class T>
void get(const uint8_t* in, T& value) {
  if constexpr (FieldShape<T>::is_array) {
    using E = typename FieldShape<T>::Element;
    for (size_t i = 0; i < value.size(); ++i) value[i] = get_scalar<E>(in + i * sizeof(E));
  } else {
    value = get_scalar<T>(in);
  }
}

}  // namespace detail

// Writes every field of `msg` at its wire offset: `out` holds max_length<M>() bytes.
template <class M>
void write_payload(const M& msg, std::span<uint8_t> out) {
  [&]<size_t... I>(std::index_sequence<I...>) {
    (detail::put(out.data() + Layout<M>::kOffsets[I], msg.*(std::get<I>(Layout<M>::kFieldList).member)), ...);
  }(std::make_index_sequence<Layout<M>::kCount>{});
}

// Reads every field from `in`, which holds max_length<M>() bytes (zero-filled past what was sent).
template <class M>
void read_payload(std::span<const uint8_t> in, M& msg) {
  [&]<size_t... I>(std::index_sequence<I...>) {
    (detail::get(in.data() + Layout<M>::kOffsets[I], msg.*(std::get<I>(Layout<M>::kFieldList).member)), ...);
  }(std::make_index_sequence<Layout<M>::kCount>{});
}

// Calls v(name, value) for every field in XML order (value is a const reference to the member).
template <class M, class V>
void for_each_field(const M& msg, V&& v) {
  std::apply([&](const auto&... f) { (v(f.name, msg.*(f.member)), ...); }, M::fields());
}
template <class M, class V>
void for_each_field(M& msg, V&& v) {
  std::apply([&](const auto&... f) { (v(f.name, msg.*(f.member)), ...); }, M::fields());
}

}  // namespace aerie::mavlink
