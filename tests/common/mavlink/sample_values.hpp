#pragma once
// Non-zero test values for every field of a catalogue message (extensions included), and the
// message as one JSON line for the node-mavlink cross-check (node_crosscheck.cjs).
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>

#include "common/mavlink/catalogue.hpp"

namespace aerie::mavlink::testing {

template <class T>
T sample_scalar(int k) {
  if constexpr (std::is_same_v<T, char>) {
    return static_cast<char>('A' + k % 26);
  } else if constexpr (std::is_floating_point_v<T>) {
    return static_cast<T>(k % 2 ? -0.25 * k - 0.1 : 0.5 * k + 1.0 / 3.0);
  } else {
    // Every byte non-zero (so that no truncation hides a field), the top bit set for k odd
    // (negative signed values, unsigned 64-bit values beyond 2^53 that a double would lose).
    using U = std::make_unsigned_t<T>;
    U bits = 0;
    for (size_t i = 0; i < sizeof(T); ++i) bits = static_cast<U>(bits | U(1 + (k * 7 + i * 13) % 120) << (8 * i));
    if (k % 2) bits = static_cast<U>(bits | (U(1) << (8 * sizeof(T) - 1)));
    return static_cast<T>(bits);
  }
}

// Every field non-zero; `seed` makes different messages of one type differ.
template <class M>
M sample(int seed = 0) {
  M msg;
  int k = seed * 101 + 1;
  for_each_field(msg, [&](std::string_view, auto& value) {
    using T = std::remove_cvref_t<decltype(value)>;
    if constexpr (FieldShape<T>::is_array) {
      for (auto& e : value) e = sample_scalar<typename FieldShape<T>::Element>(k++);
    } else {
      value = sample_scalar<T>(k++);
    }
  });
  return msg;
}

template <class T>
std::string json_scalar(T v) {
  char text[64];
  if constexpr (std::is_same_v<T, char>) {
    return "\"" + std::string(1, v) + "\"";
  } else if constexpr (std::is_same_v<T, float>) {
    std::snprintf(text, sizeof text, "%.9g", static_cast<double>(v));
  } else if constexpr (std::is_same_v<T, double>) {
    std::snprintf(text, sizeof text, "%.17g", v);
  } else if constexpr (sizeof(T) == 8) {
    return "\"" + std::to_string(v) + "\"";  // 64-bit integers as strings (JSON numbers are doubles)
  } else {
    return std::to_string(static_cast<int64_t>(v));
  }
  return text;
}

template <class M>
std::string fields_json(const M& msg) {
  std::string out = "{";
  bool first = true;
  for_each_field(msg, [&](std::string_view name, const auto& value) {
    using T = std::remove_cvref_t<decltype(value)>;
    if (!first) out += ",";
    first = false;
    out += "\"" + std::string(name) + "\":";
    if constexpr (FieldShape<T>::is_array) {
      if constexpr (std::is_same_v<typename FieldShape<T>::Element, char>) {
        out += "\"";
        for (char c : value) {
          if (c == 0) break;
          out += c;  // sample values are letters only
        }
        out += "\"";
      } else {
        out += "[";
        for (size_t i = 0; i < value.size(); ++i) out += (i ? "," : "") + json_scalar(value[i]);
        out += "]";
      }
    } else {
      out += json_scalar(value);
    }
  });
  return out + "}";
}

}  // namespace aerie::mavlink::testing
