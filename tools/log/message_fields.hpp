#pragma once
// Two encoded messages of the same catalogue type compared field by field, walking the wire
// schema that bounded decoding uses (common/bus/wire.hpp, generated from lcmtypes/*.lcm): every
// numeric field (integers, float, double, boolean, byte), in nested structs and in fixed or
// variable arrays, named by its path: "position[2]", "levels[1].u[3]", "corners[2][1]".
#include <cstddef>
#include <cstdint>
#include <string>

namespace aerie::logtools {

struct FieldDifference {
  bool comparable = false;  // both payloads are well-formed messages of one catalogue type
  std::string type;         // that type, e.g. "aerie.pose_t"
  double max_abs = 0;       // largest |a - b| over the numeric values both have (inf: NaN against a number)
  std::string field;        // the path of that value; "" when no numeric value differs
  std::string shape;        // the first array whose size differs: "levels: 2 vs 3 elements", or ""
  std::string text;         // the first string that differs: "tracker", or ""
};

// Not comparable (and nothing else set) when a payload is not a well-formed message of a
// catalogue type, or the two are of different types.
FieldDifference compare_fields(const uint8_t* a, size_t a_size, const uint8_t* b, size_t b_size);

}  // namespace aerie::logtools
