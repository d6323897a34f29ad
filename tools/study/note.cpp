#include "tools/study/note.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <utility>

namespace aerie::study {

NoteWriter& NoteWriter::real(double v) {
  char s[40];
  std::snprintf(s, sizeof s, "%.17g ", v);  // 17 significant digits: the same double back
  out_ += s;
  return *this;
}

NoteWriter& NoteWriter::integer(int64_t v) {
  out_ += std::to_string(v) + ' ';
  return *this;
}

NoteWriter& NoteWriter::text(const std::string& s) {
  out_ += std::to_string(s.size()) + ':' + s + ' ';
  return *this;
}

NoteReader::NoteReader(std::string note, std::string what) : note_(std::move(note)), what_(std::move(what)) {}

void NoteReader::fail(const std::string& why) const {
  throw std::runtime_error(what_ + " is malformed at byte " + std::to_string(at_) + ": " + why);
}

std::string NoteReader::token() {
  const size_t end = note_.find(' ', at_);
  if (end == std::string::npos) fail("expected another value, the note ends");
  std::string t = note_.substr(at_, end - at_);
  at_ = end + 1;
  return t;
}

double NoteReader::real() {
  const std::string t = token();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end) fail("expected a number, got '" + t + "'");
  return v;
}

int64_t NoteReader::integer() {
  const std::string t = token();
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(t.c_str(), &end, 10);
  if (t.empty() || *end || errno) fail("expected an integer, got '" + t + "'");
  return v;
}

std::string NoteReader::text() {
  const size_t colon = note_.find(':', at_);
  if (colon == std::string::npos) fail("expected a string");
  const std::string len = note_.substr(at_, colon - at_);
  char* end = nullptr;
  const unsigned long long n = std::strtoull(len.c_str(), &end, 10);
  if (len.empty() || *end || n > note_.size() - colon - 1 || note_.size() - colon - 1 - n < 1 || note_[colon + 1 + n] != ' ')
    fail("expected <length>:<bytes>, got '" + note_.substr(at_, 40) + "'");
  std::string s = note_.substr(colon + 1, n);
  at_ = colon + 2 + n;
  return s;
}

void NoteReader::end() const {
  if (at_ != note_.size()) fail(std::to_string(note_.size() - at_) + " bytes left over");
}

}  // namespace aerie::study
