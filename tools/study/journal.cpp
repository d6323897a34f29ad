#include "tools/study/journal.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace aerie::study {

namespace {

namespace fs = std::filesystem;

std::string header_of(const Study& study) {
  std::string names;
  for (const auto& o : study.outputs) {
    if (o.name.empty() || o.name.find_first_of(" \n/") != std::string::npos)
      throw std::invalid_argument("study " + study.dir + ": output name '" + o.name +
                                  "' must be a plain file name (no spaces or '/')");
    names += " " + o.name;
  }
  return "aerie-study 1\nruns " + std::to_string(study.runs) + "\noutputs " + std::to_string(study.outputs.size()) +
         names + "\ndefinition " + std::to_string(study.definition.size()) + "\n" + study.definition + "\n";
}

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// One journal record; false when the bytes from `pos` do not hold a complete one.
struct Parsed {
  char kind = 0;
  int index = 0;
  bool failed = false;
  std::vector<long long> numbers;  // sizes (w) or row lengths (h)
  Record record;
};
bool parse_record(const std::string& s, size_t& pos, size_t outputs, Parsed& p) {
  const size_t eol = s.find('\n', pos);
  if (eol == std::string::npos) return false;
  std::istringstream line(s.substr(pos, eol - pos));
  std::string kind, status;
  long long note = -1, error = -1;
  line >> kind >> p.index >> status;
  p.numbers.assign(outputs, -1);
  for (auto& n : p.numbers) line >> n;
  line >> note >> error;
  if (!line || (kind != "w" && kind != "h") || (status != "o" && status != "f") || note < 0 || error < 0) return false;
  for (long long n : p.numbers)
    if (n < 0) return false;
  p.kind = kind[0];
  p.failed = status == "f";
  size_t at = eol + 1;
  long long payload = note + error + 1;
  if (p.kind == 'h')
    for (long long n : p.numbers) payload += n;
  if (static_cast<long long>(s.size() - at) < payload || s[at + static_cast<size_t>(payload) - 1] != '\n') return false;
  p.record = Record{};
  if (p.kind == 'h')
    for (long long n : p.numbers) {
      p.record.rows.push_back(s.substr(at, static_cast<size_t>(n)));
      at += static_cast<size_t>(n);
    }
  p.record.note = s.substr(at, static_cast<size_t>(note));
  p.record.error = s.substr(at + static_cast<size_t>(note), static_cast<size_t>(error));
  pos = at + static_cast<size_t>(note + error) + 1;
  return true;
}

std::string record_line(char kind, int index, const Record& r, const std::vector<long long>& numbers) {
  std::string line = std::string(1, kind) + " " + std::to_string(index) + (r.failed() ? " f" : " o");
  for (long long n : numbers) line += " " + std::to_string(n);
  return line + " " + std::to_string(r.note.size()) + " " + std::to_string(r.error.size()) + "\n";
}

std::FILE* open_append(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "ab");
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  return f;
}

void put(std::FILE* f, const std::string& bytes, const std::string& path) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fflush(f) != 0)
    throw std::runtime_error(path + ": write failed");
}

}  // namespace

Journal::Journal(const Study& study, bool resume) : study_(study), path_(study.dir + "/study.progress") {
  const std::string header = header_of(study);
  bool fresh = !resume || !fs::exists(path_);
  if (resume && fresh)
    for (const auto& o : study.outputs)
      if (fs::exists(study.dir + "/" + o.name))
        throw std::runtime_error(path_ + ": not found, but " + study.dir + "/" + o.name +
                                 " exists: not a resumable study folder (start it again with --out)");
  std::vector<long long> sizes;
  std::vector<Parsed> written;
  if (fresh) {
    fs::create_directories(study.dir);
    for (const auto& o : study.outputs) {
      const std::string p = study.dir + "/" + o.name;
      std::FILE* f = std::fopen(p.c_str(), "wb");
      if (!f) throw std::runtime_error(p + ": cannot create");
      files_.push_back(f);
      put(f, o.header, p);
    }
    journal_ = std::fopen(path_.c_str(), "wb");
    if (!journal_) throw std::runtime_error(path_ + ": cannot create");
    put(journal_, header, path_);
    return;
  }
  const std::string s = read_all(path_);
  if (s.compare(0, header.size(), header) != 0)
    throw std::runtime_error(path_ + ": the study there is not this one (its runs, outputs or definition differ:"
                             " resume with the options it was started with); it begins\n" +
                             s.substr(0, std::min<size_t>(s.size(), header.size() + 200)));
  size_t pos = header.size(), end = pos;
  for (const auto& o : study.outputs) sizes.push_back(static_cast<long long>(o.header.size()));
  Parsed p;
  while (parse_record(s, pos, study.outputs.size(), p)) {
    if (p.index < 0 || p.index >= study.runs)
      throw std::runtime_error(path_ + ": record of run " + std::to_string(p.index) + ", the study has " +
                               std::to_string(study.runs) + " runs");
    if (p.kind == 'w') {
      if (p.index != next_)
        throw std::runtime_error(path_ + ": run " + std::to_string(p.index) + " written after run " +
                                 std::to_string(next_ - 1) + " (runs are written in index order)");
      ++next_;
      sizes = p.numbers;
      held_.erase(p.index);
      written.push_back(std::move(p));
    } else if (p.index >= next_) {
      held_[p.index] = std::move(p.record);
    }
    end = pos;
  }
  fs::resize_file(path_, end);  // a record torn by the process's death goes
  for (size_t k = 0; k < study.outputs.size(); ++k) {
    const std::string op = study.dir + "/" + study.outputs[k].name;
    const auto have = fs::exists(op) ? static_cast<long long>(fs::file_size(op)) : -1;
    if (have < sizes[k])
      throw std::runtime_error(op + ": " + std::to_string(have) + " bytes, the journal " + path_ + " says " +
                               std::to_string(sizes[k]) + " were written: was it edited or replaced?");
    const std::string& want = study.outputs[k].header;
    std::ifstream in(op, std::ios::binary);
    std::string got(want.size(), '\0');
    in.read(got.data(), static_cast<std::streamsize>(got.size()));
    if (got != want) throw std::runtime_error(op + ": its header is not this study's (" + want.substr(0, 60) + "...)");
    fs::resize_file(op, static_cast<uintmax_t>(sizes[k]));  // rows written after the last complete run go
    files_.push_back(open_append(op));
  }
  journal_ = open_append(path_);
  resumed_ = next_ + static_cast<int>(held_.size());
  for (auto& w : written) {
    if (w.failed) {
      ++failed_;
      std::fprintf(stderr, "%s: %s failed (earlier in this study): %s\n", study.tool.c_str(),
                   study.describe(w.index).c_str(), w.record.error.c_str());
    }
    if (study.on_written) study.on_written(w.index, w.record);
  }
  for (const auto& [index, r] : held_)
    if (r.failed()) {
      ++failed_;
      std::fprintf(stderr, "%s: %s failed (earlier in this study): %s\n", study.tool.c_str(),
                   study.describe(index).c_str(), r.error.c_str());
    }
  while (held_.count(next_)) {
    auto node = held_.extract(next_);
    write(next_, node.mapped());
  }
}

Journal::~Journal() {
  for (std::FILE* f : files_) std::fclose(f);
  if (journal_) std::fclose(journal_);
}

void Journal::append_journal(const std::string& bytes) { put(journal_, bytes, path_); }

void Journal::write(int index, const Record& r) {
  std::vector<long long> sizes;
  for (size_t k = 0; k < files_.size(); ++k) {
    const std::string p = study_.dir + "/" + study_.outputs[k].name;
    if (k < r.rows.size()) put(files_[k], r.rows[k], p);
    sizes.push_back(static_cast<long long>(std::ftell(files_[k])));
  }
  append_journal(record_line('w', index, r, sizes) + r.note + r.error + "\n");
  ++next_;
  if (study_.on_written) study_.on_written(index, r);
}

void Journal::complete(int index, Record r) {
  if (index < 0 || index >= study_.runs || done(index))
    throw std::logic_error(path_ + ": run " + std::to_string(index) + " completed twice or out of range");
  if (r.failed()) {
    r.rows.clear();
    ++failed_;
    std::fprintf(stderr, "%s: %s failed: %s\n", study_.tool.c_str(), study_.describe(index).c_str(), r.error.c_str());
  }
  if (r.rows.size() > files_.size())
    throw std::logic_error(path_ + ": run " + std::to_string(index) + " has rows for " + std::to_string(r.rows.size()) +
                           " files, the study " + std::to_string(files_.size()));
  if (index != next_) {
    std::vector<long long> lengths;
    std::string rows;
    for (size_t k = 0; k < files_.size(); ++k) {
      const std::string& part = k < r.rows.size() ? r.rows[k] : std::string();
      lengths.push_back(static_cast<long long>(part.size()));
      rows += part;
    }
    append_journal(record_line('h', index, r, lengths) + rows + r.note + r.error + "\n");
    held_[index] = std::move(r);
    return;
  }
  write(index, r);
  while (held_.count(next_)) {
    auto node = held_.extract(next_);
    write(next_, node.mapped());
  }
}

}  // namespace aerie::study
