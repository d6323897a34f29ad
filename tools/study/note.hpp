#pragma once
// A run's note (Record::note) as a list of values that come back exactly: doubles as %.17g
// (NaN and infinities too), integers, and strings with their length. Studies use it to carry
// what their summaries and reports need from runs flown on other ranks or before a --resume.
#include <cstdint>
#include <string>

namespace aerie::study {

class NoteWriter {
 public:
  NoteWriter& real(double v);
  NoteWriter& integer(int64_t v);
  NoteWriter& text(const std::string& s);  // any bytes
  const std::string& str() const { return out_; }

 private:
  std::string out_;
};

// Reads the values in the order they were written; throws std::runtime_error naming `what`
// (e.g. "aerie-bench-avoidance: run 3's note") when the note holds fewer or other values.
class NoteReader {
 public:
  NoteReader(std::string note, std::string what);
  double real();
  int64_t integer();
  std::string text();
  void end() const;  // throws when values are left over

 private:
  std::string token();
  [[noreturn]] void fail(const std::string& why) const;
  std::string note_, what_;
  size_t at_ = 0;
};

}  // namespace aerie::study
