#include "procman/command_line.hpp"

#include <cctype>
#include <cstdlib>
#include <stdexcept>

namespace aerie::procman {

VariableLookup environment_lookup() {
  return [](const std::string& name) -> std::optional<std::string> {
    const char* v = std::getenv(name.c_str());
    if (!v) return std::nullopt;
    return std::string(v);
  };
}

namespace {

bool name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

class Splitter {
 public:
  Splitter(const std::string& s, const VariableLookup& lookup) : s_(s), lookup_(lookup) {}

  struct Word {
    std::string text;
    bool literal_name = true;  // unquoted, unexpanded text up to the first '='
  };

  std::vector<Word> words() {
    std::vector<Word> out;
    while (true) {
      while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
      if (i_ >= s_.size()) return out;
      out.push_back(word());
    }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument("exec \"" + s_ + "\": " + what);
  }

  Word word() {
    Word result;
    std::string& w = result.text;
    bool seen_eq = false;
    while (i_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[i_]))) {
      const char c = s_[i_];
      if (c == '=') seen_eq = true;
      if (!seen_eq && (c == '\'' || c == '"' || c == '\\' || c == '$')) result.literal_name = false;
      if (c == '\'') {
        const size_t end = s_.find('\'', i_ + 1);
        if (end == std::string::npos) fail("unterminated single quote at column " + std::to_string(i_ + 1));
        w += s_.substr(i_ + 1, end - i_ - 1);
        i_ = end + 1;
      } else if (c == '"') {
        const size_t start = i_++;
        while (true) {
          if (i_ >= s_.size()) fail("unterminated double quote at column " + std::to_string(start + 1));
          const char d = s_[i_];
          if (d == '"') {
            ++i_;
            break;
          }
          if (d == '\\' && i_ + 1 < s_.size() && std::string("\"\\$`").find(s_[i_ + 1]) != std::string::npos) {
            w += s_[i_ + 1];
            i_ += 2;
          } else if (d == '$') {
            w += variable();
          } else {
            w += d;
            ++i_;
          }
        }
      } else if (c == '\\') {
        if (i_ + 1 >= s_.size()) fail("trailing backslash");
        w += s_[i_ + 1];
        i_ += 2;
      } else if (c == '$') {
        w += variable();
      } else {
        w += c;
        ++i_;
      }
    }
    return result;
  }

  // At '$': $NAME, ${NAME} or ${NAME:-default}. A '$' not followed by a name is literal.
  std::string variable() {
    const size_t start = i_++;
    if (i_ < s_.size() && s_[i_] == '{') {
      const size_t close = s_.find('}', i_);
      if (close == std::string::npos) fail("missing '}' for the variable at column " + std::to_string(start + 1));
      const std::string body = s_.substr(i_ + 1, close - i_ - 1);
      i_ = close + 1;
      const size_t dflt = body.find(":-");
      const std::string name = body.substr(0, dflt);
      if (name.empty() || !name_start(name[0]) ||
          name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") !=
              std::string::npos)
        fail("bad variable name '${" + body + "}'");
      if (auto v = lookup_(name); v && !(dflt != std::string::npos && v->empty())) return *v;
      if (dflt != std::string::npos) return body.substr(dflt + 2);
      fail("environment variable " + name + " is not set (give a default with ${" + name + ":-value})");
    }
    if (i_ >= s_.size() || !name_start(s_[i_])) return "$";
    const size_t b = i_;
    while (i_ < s_.size() && name_char(s_[i_])) ++i_;
    const std::string name = s_.substr(b, i_ - b);
    if (auto v = lookup_(name)) return *v;
    fail("environment variable " + name + " is not set (give a default with ${" + name + ":-value})");
  }

  const std::string& s_;
  const VariableLookup& lookup_;
  size_t i_ = 0;
};

// NAME=value with a valid shell name, written literally, before '='.
bool is_assignment(const std::string& w, bool literal_name) {
  const size_t eq = w.find('=');
  if (!literal_name) return false;
  if (eq == std::string::npos || eq == 0 || !name_start(w[0])) return false;
  for (size_t k = 1; k < eq; ++k)
    if (!name_char(w[k])) return false;
  return true;
}

}  // namespace

CommandLine split_command_line(const std::string& exec, const VariableLookup& lookup) {
  // As in a shell, only a literally written NAME= makes an assignment.
  CommandLine out;
  const auto words = Splitter(exec, lookup).words();
  size_t k = 0;
  for (; k < words.size() && is_assignment(words[k].text, words[k].literal_name); ++k) {
    const size_t eq = words[k].text.find('=');
    out.env.emplace_back(words[k].text.substr(0, eq), words[k].text.substr(eq + 1));
  }
  for (; k < words.size(); ++k) out.argv.push_back(words[k].text);
  if (out.argv.empty()) throw std::invalid_argument("exec \"" + exec + "\": no program to run");
  return out;
}

}  // namespace aerie::procman
