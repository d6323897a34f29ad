#include "procman/pmd_config.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace aerie::procman {

PmdError::PmdError(const std::string& origin, int line, int column, const std::string& message)
    : std::runtime_error(origin + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message),
      line_(line),
      column_(column) {}

namespace {

constexpr double kMaxStopTimeAllowed = 3600;  // s before SIGKILL (libbot2 sets no bound; this keeps it a finite float)

enum class Tok { Identifier, String, Number, Assign, Semicolon, Open, Close, End };

struct Token {
  Tok type = Tok::End;
  std::string text;
  int line = 1, column = 1;
};

std::string describe(const Token& t) {
  switch (t.type) {
    case Tok::Identifier: return "'" + t.text + "'";
    case Tok::String: return "string \"" + t.text + "\"";
    case Tok::Number: return "number " + t.text;
    case Tok::End: return "end of file";
    default: return "'" + t.text + "'";
  }
}

class Lexer {
 public:
  Lexer(const std::string& text, const std::string& origin) : s_(text), origin_(origin) {}

  Token next() {
    skip_space_and_comments();
    Token t;
    t.line = line_;
    t.column = col_;
    if (pos_ >= s_.size()) return t;
    const char c = s_[pos_];
    if (c == '=' || c == ';' || c == '{' || c == '}') {
      t.type = c == '=' ? Tok::Assign : c == ';' ? Tok::Semicolon : c == '{' ? Tok::Open : Tok::Close;
      t.text = std::string(1, c);
      advance();
      return t;
    }
    if (c == '"') return string_literal(t);
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      t.type = Tok::Identifier;
      while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_' ||
                                  s_[pos_] == '-'))
        t.text += advance();
      return t;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '.') {
      t.type = Tok::Number;
      if (c == '-') t.text += advance();
      while (pos_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.'))
        t.text += advance();
      if (t.text.find_first_of("0123456789") == std::string::npos || std::count(t.text.begin(), t.text.end(), '.') > 1)
        throw PmdError(origin_, t.line, t.column, "malformed number '" + t.text + "'");
      return t;
    }
    throw PmdError(origin_, t.line, t.column, std::string("unexpected character '") + c + "'");
  }

 private:
  char advance() {
    const char c = s_[pos_++];
    if (c == '\n') {
      ++line_;
      col_ = 1;
    } else {
      ++col_;
    }
    return c;
  }
  void skip_space_and_comments() {
    while (pos_ < s_.size()) {
      if (std::isspace(static_cast<unsigned char>(s_[pos_]))) {
        advance();
      } else if (s_[pos_] == '#') {
        while (pos_ < s_.size() && s_[pos_] != '\n') advance();
      } else {
        break;
      }
    }
  }
  Token string_literal(Token t) {
    t.type = Tok::String;
    advance();  // opening quote
    while (true) {
      if (pos_ >= s_.size() || s_[pos_] == '\n')
        throw PmdError(origin_, t.line, t.column, "unterminated string (missing closing '\"')");
      char c = advance();
      if (c == '"') return t;
      if (c == '\\') {
        if (pos_ >= s_.size()) throw PmdError(origin_, t.line, t.column, "unterminated string");
        const char e = advance();
        c = e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e;
      }
      t.text += c;
    }
  }

  const std::string& s_;
  const std::string& origin_;
  size_t pos_ = 0;
  int line_ = 1, col_ = 1;
};

class Parser {
 public:
  Parser(const std::string& text, const std::string& origin) : lex_(text, origin), origin_(origin) {
    cur_ = lex_.next();
  }

  PmdConfig parse() {
    PmdConfig cfg;
    cfg.origin = origin_;
    while (cur_.type != Tok::End) {
      const Token kw = expect(Tok::Identifier, "'cmd', 'group' or 'script'");
      if (kw.text == "cmd") {
        cfg.commands.push_back(command("", kw));
      } else if (kw.text == "group") {
        group("", cfg, kw, 1);
      } else if (kw.text == "script") {
        cfg.scripts.push_back(script(kw));
      } else {
        fail(kw, "expected 'cmd', 'group' or 'script', found " + describe(kw));
      }
    }
    return cfg;
  }

 private:
  [[noreturn]] void fail(const Token& at, const std::string& message) {
    throw PmdError(origin_, at.line, at.column, message);
  }
  Token take() {
    Token t = cur_;
    cur_ = lex_.next();
    return t;
  }
  Token expect(Tok type, const std::string& what) {
    if (cur_.type != type) fail(cur_, "expected " + what + ", found " + describe(cur_));
    return take();
  }
  bool accept(Tok type) {
    if (cur_.type != type) return false;
    take();
    return true;
  }
  std::string name_string(const std::string& what) {
    const Token t = expect(Tok::String, what + " in double quotes");
    if (t.text.empty() || t.text.find_first_not_of(" \t") == std::string::npos) fail(t, what + " is empty");
    if (t.text.find('/') != std::string::npos) fail(t, "'/' is not allowed in " + what + " \"" + t.text + "\"");
    return t.text;
  }

  PmdCommand command(const std::string& group_path, const Token& kw) {
    PmdCommand c;
    c.line = kw.line;
    c.column = kw.column;
    c.group = group_path;
    if (cur_.type == Tok::String) c.name = name_string("command name");
    expect(Tok::Open, "'{' after cmd");
    std::set<std::string> seen;
    while (cur_.type == Tok::Identifier) {
      const Token key = take();
      if (!seen.insert(key.text).second) fail(key, "attribute '" + key.text + "' given twice");
      expect(Tok::Assign, "'=' after '" + key.text + "'");
      if (key.text == "exec" || key.text == "host" || key.text == "group" || key.text == "auto_respawn") {
        const Token v = expect(Tok::String, "a string value for '" + key.text + "'");
        if (key.text == "exec") {
          c.exec = v.text;
        } else if (key.text == "host") {
          c.host = v.text;
        } else if (key.text == "group") {
          if (!group_path.empty()) fail(key, "'group' attribute inside group \"" + group_path + "\"");
          c.group = v.text;
        } else {
          if (v.text != "true" && v.text != "false")
            fail(v, "auto_respawn must be \"true\" or \"false\", found \"" + v.text + "\"");
          c.auto_respawn = v.text == "true";
        }
      } else if (key.text == "stop_signal" || key.text == "stop_time_allowed") {
        const Token v = expect(Tok::Number, "a number for '" + key.text + "'");
        const double x = std::strtod(v.text.c_str(), nullptr);  // [-]digits[.digits]; inf when too long
        if (key.text == "stop_signal") {
          if (!(x >= 1 && x <= 64) || x != std::floor(x))
            fail(v, "stop_signal must be a signal number 1..64, found " + v.text);
          c.stop_signal = static_cast<int>(x);
        } else {
          if (!(x > 0 && x <= kMaxStopTimeAllowed))
            fail(v, "stop_time_allowed must be in (0, " + std::to_string(static_cast<int>(kMaxStopTimeAllowed)) +
                        "] seconds, found " + v.text);
          c.stop_time_allowed_s = x;
        }
      } else {
        fail(key, "unknown attribute '" + key.text +
                      "' (expected exec, host, group, auto_respawn, stop_signal or stop_time_allowed)");
      }
      expect(Tok::Semicolon, "';' after the value of '" + key.text + "'");
    }
    expect(Tok::Close, "an attribute or '}'");
    if (c.exec.empty()) fail(kw, "command" + (c.name.empty() ? std::string() : " \"" + c.name + "\"") + " has no exec");
    if (c.host.empty()) fail(kw, "command" + (c.name.empty() ? std::string() : " \"" + c.name + "\"") + " has no host");
    if (c.name.empty()) c.name = c.exec;  // libbot2 shows the exec string for unnamed commands
    return c;
  }

  void group(const std::string& parent, PmdConfig& cfg, const Token& kw, int depth) {
    if (depth > kMaxGroupDepth)
      fail(kw, "groups nested more than " + std::to_string(kMaxGroupDepth) + " deep (in \"" + parent + "\")");
    const std::string name = name_string("group name");
    const std::string path = parent.empty() ? name : parent + "/" + name;
    expect(Tok::Open, "'{' after group name");
    while (cur_.type == Tok::Identifier) {
      const Token kw = take();
      if (kw.text == "cmd") {
        cfg.commands.push_back(command(path, kw));
      } else if (kw.text == "group") {
        group(path, cfg, kw, depth + 1);
      } else {
        fail(kw, "expected 'cmd' or 'group' inside group \"" + path + "\", found " + describe(kw));
      }
    }
    expect(Tok::Close, "'cmd', 'group' or '}'");
  }

  WaitFor status_string() {
    const Token t = expect(Tok::String, "\"running\" or \"stopped\"");
    if (t.text == "running") return WaitFor::Running;
    if (t.text == "stopped") return WaitFor::Stopped;
    fail(t, "expected \"running\" or \"stopped\", found \"" + t.text + "\"");
  }

  PmdScript script(const Token& kw) {
    PmdScript s;
    s.line = kw.line;
    s.column = kw.column;
    s.name = expect(Tok::String, "script name in double quotes").text;
    if (s.name.empty()) fail(kw, "script name is empty");
    expect(Tok::Open, "'{' after script name");
    while (cur_.type == Tok::Identifier) {
      const Token a = take();
      ScriptAction act;
      act.line = a.line;
      act.column = a.column;
      if (a.text == "start" || a.text == "stop" || a.text == "restart") {
        act.kind = a.text == "start" ? ActionKind::Start : a.text == "stop" ? ActionKind::Stop : ActionKind::Restart;
        const Token what = expect(Tok::Identifier, "'everything', 'group' or 'cmd'");
        if (what.text == "everything") {
          act.target = TargetKind::Everything;
        } else if (what.text == "group" || what.text == "cmd") {
          act.target = what.text == "group" ? TargetKind::Group : TargetKind::Command;
          act.ident = expect(Tok::String, what.text + " name in double quotes").text;
        } else {
          fail(what, "expected 'everything', 'group' or 'cmd', found " + describe(what));
        }
        if (cur_.type == Tok::Identifier && cur_.text == "wait") {
          take();
          act.wait = status_string();
        }
      } else if (a.text == "wait") {
        const Token what = expect(Tok::Identifier, "'ms', 'cmd' or 'group' after wait");
        if (what.text == "ms") {
          act.kind = ActionKind::WaitMs;
          const Token n = expect(Tok::Number, "a duration in milliseconds");
          if (n.text.find_first_of(".-") != std::string::npos) fail(n, "wait ms needs a non-negative integer");
          if (std::from_chars(n.text.data(), n.text.data() + n.text.size(), act.wait_ms).ec != std::errc())
            fail(n, "wait ms " + n.text + " is out of range");
        } else if (what.text == "cmd" || what.text == "group") {
          act.kind = ActionKind::WaitStatus;
          act.target = what.text == "group" ? TargetKind::Group : TargetKind::Command;
          act.ident = expect(Tok::String, what.text + " name in double quotes").text;
          const Token st = expect(Tok::Identifier, "'status'");
          if (st.text != "status") fail(st, "expected 'status', found " + describe(st));
          act.wait = status_string();
        } else {
          fail(what, "expected 'ms', 'cmd' or 'group' after wait, found " + describe(what));
        }
      } else if (a.text == "run_script") {
        act.kind = ActionKind::RunScript;
        act.ident = expect(Tok::String, "script name in double quotes").text;
      } else {
        fail(a, "unknown script action " + describe(a) + " (expected start, stop, restart, wait or run_script)");
      }
      expect(Tok::Semicolon, "';' at the end of the action");
      s.actions.push_back(std::move(act));
    }
    expect(Tok::Close, "a script action or '}'");
    return s;
  }

  Lexer lex_;
  const std::string& origin_;
  Token cur_;
};

void validate(const PmdConfig& cfg) {
  std::map<std::string, const PmdCommand*> names;
  std::set<std::string> groups;
  for (const auto& c : cfg.commands) {
    auto [it, fresh] = names.emplace(c.name, &c);
    if (!fresh)
      throw PmdError(cfg.origin, c.line, c.column,
                     "command \"" + c.name + "\" is defined twice (first at line " + std::to_string(it->second->line) + ")");
    for (std::string g = c.group; !g.empty();) {  // the group and every parent
      groups.insert(g);
      const auto slash = g.rfind('/');
      g = slash == std::string::npos ? "" : g.substr(0, slash);
    }
  }
  std::map<std::string, const PmdScript*> scripts;
  for (const auto& s : cfg.scripts) {
    auto [it, fresh] = scripts.emplace(s.name, &s);
    if (!fresh)
      throw PmdError(cfg.origin, s.line, s.column,
                     "script \"" + s.name + "\" is defined twice (first at line " + std::to_string(it->second->line) + ")");
  }
  for (const auto& s : cfg.scripts) {
    for (const auto& a : s.actions) {
      if (a.kind == ActionKind::RunScript && !scripts.count(a.ident))
        throw PmdError(cfg.origin, a.line, a.column, "run_script: no script named \"" + a.ident + "\"");
      if (a.kind != ActionKind::RunScript && a.kind != ActionKind::WaitMs) {
        if (a.target == TargetKind::Command && !names.count(a.ident))
          throw PmdError(cfg.origin, a.line, a.column, "no command named \"" + a.ident + "\"");
        if (a.target == TargetKind::Group && !groups.count(a.ident))
          throw PmdError(cfg.origin, a.line, a.column, "no group named \"" + a.ident + "\"");
      }
    }
  }
  // run_script cycles would never end; chains are bounded (the recursion below, and the
  // sheriff's script stack, are at most kMaxRunScriptDepth deep). height: the longest chain
  // from a script, once known.
  std::map<std::string, int> mark;  // 0 new, 1 on stack, 2 done
  std::map<std::string, int> height;
  std::function<void(const PmdScript&, int)> visit = [&](const PmdScript& s, int depth) {
    mark[s.name] = 1;
    int h = 1;
    for (const auto& a : s.actions) {
      if (a.kind != ActionKind::RunScript) continue;
      const PmdScript& t = *scripts.at(a.ident);
      if (mark[t.name] == 1)
        throw PmdError(cfg.origin, a.line, a.column, "run_script \"" + a.ident + "\" makes a cycle of scripts");
      if (depth >= kMaxRunScriptDepth || (mark[t.name] == 2 && depth + height[t.name] > kMaxRunScriptDepth))
        throw PmdError(cfg.origin, a.line, a.column,
                       "run_script \"" + a.ident + "\" chains scripts more than " + std::to_string(kMaxRunScriptDepth) +
                           " deep");
      if (mark[t.name] == 0) visit(t, depth + 1);
      h = std::max(h, 1 + height[t.name]);
    }
    height[s.name] = h;
    mark[s.name] = 2;
  };
  for (const auto& s : cfg.scripts)
    if (mark[s.name] == 0) visit(s, 1);
}

std::string quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string number(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

}  // namespace

const PmdScript* PmdConfig::find_script(const std::string& name) const {
  for (const auto& s : scripts)
    if (s.name == name) return &s;
  return nullptr;
}

const PmdCommand* PmdConfig::find_command(const std::string& name) const {
  for (const auto& c : commands)
    if (c.name == name) return &c;
  return nullptr;
}

std::vector<std::string> PmdConfig::hosts() const {
  std::vector<std::string> out;
  for (const auto& c : commands)
    if (std::find(out.begin(), out.end(), c.host) == out.end()) out.push_back(c.host);
  return out;
}

bool group_contains(const std::string& prefix, const std::string& group) {
  if (prefix.empty()) return true;
  return group == prefix || (group.size() > prefix.size() && group.compare(0, prefix.size(), prefix) == 0 &&
                             group[prefix.size()] == '/');
}

PmdConfig parse_pmd(const std::string& text, const std::string& origin) {
  PmdConfig cfg = Parser(text, origin).parse();
  validate(cfg);
  return cfg;
}

PmdConfig load_pmd(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read procman config '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_pmd(ss.str(), path);
}

const char* to_string(WaitFor w) {
  switch (w) {
    case WaitFor::Running: return "running";
    case WaitFor::Stopped: return "stopped";
    default: return "";
  }
}

std::string to_pmd(const PmdConfig& config) {
  std::ostringstream os;
  auto write_cmd = [&](const PmdCommand& c, const std::string& indent, bool in_group) {
    os << indent << "cmd " << (c.name == c.exec ? std::string() : quote(c.name) + " ") << "{\n";
    os << indent << "    exec = " << quote(c.exec) << ";\n";
    os << indent << "    host = " << quote(c.host) << ";\n";
    if (!in_group && !c.group.empty()) os << indent << "    group = " << quote(c.group) << ";\n";
    if (c.auto_respawn) os << indent << "    auto_respawn = \"true\";\n";
    os << indent << "    stop_signal = " << c.stop_signal << ";\n";
    os << indent << "    stop_time_allowed = " << number(c.stop_time_allowed_s) << ";\n";
    os << indent << "}\n";
  };
  // Commands keep their order; consecutive commands of one group share a block.
  // Group paths are written as nested blocks.
  std::vector<std::string> open;  // currently open group names
  auto split = [](const std::string& g) {
    std::vector<std::string> parts;
    std::string cur;
    for (char c : g) {
      if (c == '/') {
        parts.push_back(cur);
        cur.clear();
      } else {
        cur += c;
      }
    }
    if (!g.empty()) parts.push_back(cur);
    return parts;
  };
  for (const auto& c : config.commands) {
    const auto parts = split(c.group);
    size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) ++common;
    while (open.size() > common) {
      open.pop_back();
      os << std::string(4 * open.size(), ' ') << "}\n";
    }
    while (open.size() < parts.size()) {
      os << std::string(4 * open.size(), ' ') << "group " << quote(parts[open.size()]) << " {\n";
      open.push_back(parts[open.size()]);
    }
    write_cmd(c, std::string(4 * open.size(), ' '), true);
  }
  while (!open.empty()) {
    open.pop_back();
    os << std::string(4 * open.size(), ' ') << "}\n";
  }
  for (const auto& s : config.scripts) {
    os << "\nscript " << quote(s.name) << " {\n";
    for (const auto& a : s.actions) {
      os << "    ";
      switch (a.kind) {
        case ActionKind::Start:
        case ActionKind::Stop:
        case ActionKind::Restart:
          os << (a.kind == ActionKind::Start ? "start " : a.kind == ActionKind::Stop ? "stop " : "restart ");
          if (a.target == TargetKind::Everything)
            os << "everything";
          else
            os << (a.target == TargetKind::Group ? "group " : "cmd ") << quote(a.ident);
          if (a.wait != WaitFor::Nothing) os << " wait " << quote(to_string(a.wait));
          break;
        case ActionKind::WaitMs: os << "wait ms " << a.wait_ms; break;
        case ActionKind::WaitStatus:
          os << "wait " << (a.target == TargetKind::Group ? "group " : "cmd ") << quote(a.ident) << " status "
             << quote(to_string(a.wait));
          break;
        case ActionKind::RunScript: os << "run_script " << quote(a.ident); break;
      }
      os << ";\n";
    }
    os << "}\n";
  }
  return os.str();
}

}  // namespace aerie::procman
