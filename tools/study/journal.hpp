#pragma once
// The study's writer: output files in index order and the journal (DIR/study.progress) that
// makes them resumable. Journal records, each appended and flushed whole:
//   w <index> <o|f> <size of each output after the run's rows> <note length> <error length>\n
//     <note><error>\n                       the run's rows are in the outputs, up to those sizes
//   h <index> <o|f> <length of each output's rows> <note length> <error length>\n
//     <rows...><note><error>\n              finished before an earlier run: held until its turn
// A resume truncates every output to the sizes of the last complete `w` (a row half written
// when the process died goes) and the journal to its last complete record.
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "tools/study/study.hpp"

namespace aerie::study {

class Journal {
 public:
  // Creates the folder and the files (truncating old ones), or, with `resume`, reopens them
  // (a folder without a journal and without outputs starts afresh).
  Journal(const Study& study, bool resume);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  bool done(int index) const { return index < next_ || held_.count(index); }
  // Run `index` finished: written now if every earlier run is, else held (journaled).
  void complete(int index, Record record);
  int resumed() const { return resumed_; }
  int failed() const { return failed_; }
  const std::string& path() const { return path_; }

 private:
  void write(int index, const Record& record);
  void append_journal(const std::string& bytes);

  const Study& study_;
  std::string path_;
  std::vector<std::FILE*> files_;
  std::FILE* journal_ = nullptr;
  std::map<int, Record> held_;
  int next_ = 0, resumed_ = 0, failed_ = 0;
};

}  // namespace aerie::study
